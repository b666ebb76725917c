#!/bin/sh
# --pixels kitty inside tmux (issue 31, defect 10): tmux does not pass kitty
# images through, so rtsh draws half blocks and says why, instead of a
# blank picture.
set -u
sock=rtsh-e2e-$$
tmux() { command tmux -L "$sock" -f /dev/null "$@"; }
s=rtsh-kitty-$$
fail() { echo "FAIL: $*"; tmux kill-server 2>/dev/null; exit 1; }
screen() { tmux capture-pane -t "$s" -p; }
tmux new-session -d -s "$s" -x 100 -y 30 \
	"env TERM=tmux-256color COLORTERM=truecolor HOME='$TMP' '$RTSH' -t 1 --pixels kitty scenes/showcase.rt; exec sleep 60" ||
	fail "tmux"
for i in $(seq 1 100); do
	case $(screen) in *"rtsh>"*"│"*|*"│"*"rtsh>"*) break ;; esac
	sleep 0.1
done
sleep 1
n=$(screen | grep -o '▀\|▄' | wc -l)
[ "$n" -gt 500 ] || fail "a blank picture: $n half blocks"
screen | grep -q 'kitty images do not show in this tmux pane' || fail "no word about kitty in tmux:
$(screen | grep '│' | tail -n 1)"
tmux kill-server
echo ok
