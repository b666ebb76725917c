#!/bin/sh
# The 256-colour notice is short (issue 31, friction 6): inside tmux without
# COLORTERM, at 80 columns, the status line still shows the mode and the
# samples after it.
set -u
sock=rtsh-e2e-$$
tmux() { command tmux -L "$sock" -f /dev/null "$@"; }
s=rtsh-notice-$$
fail() { echo "FAIL: $*"; tmux kill-server 2>/dev/null; exit 1; }
screen() { tmux capture-pane -t "$s" -p; }
tmux new-session -d -s "$s" -x 80 -y 24 \
	"env -u COLORTERM TERM=tmux-256color HOME='$TMP' '$RTSH' -t 1 scenes/showcase.rt; exec sleep 60" || fail "tmux"
for i in $(seq 1 100); do
	case $(screen) in *"256 colours"*) break ;; esac
	sleep 0.1
done
line=$(screen | grep '256 colours') || fail "no 256-colour notice:
$(screen | tail -n 3)"
case $line in *"--color truecolor"*"whitted"*"spp"*) ;; *) fail "the notice pushes the status line off: $line" ;; esac
tmux kill-server
echo ok
