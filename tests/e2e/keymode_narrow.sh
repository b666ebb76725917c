#!/bin/sh
# Key mode's status line fits the width (issue 31, friction 3): at 80x24, on
# a model with a long name in path mode, the line still shows the selection,
# the samples and the step (the timings, depth, size, name and mode are left
# out first, rtsh(1) KEY MODE), and it is no wider than the screen.
set -u
sock=rtsh-e2e-$$
tmux() { command tmux -L "$sock" -f /dev/null "$@"; }
s=rtsh-narrow-$$
fail() { echo "FAIL: $*"; tmux kill-server 2>/dev/null; exit 1; }
screen() { tmux capture-pane -t "$s" -p; }
wait_for() {
	for i in $(seq 1 100); do
		case $(screen) in *"$1"*) return 0 ;; esac
		sleep 0.1
	done
	fail "$2; the screen ends with:
$(screen | tail -n 4)"
}
mkdir -p "$TMP/m"
cp scenes/models/spot/spot_triangulated.obj "$TMP/m/a_model_with_a_long_name_indeed.obj"
tmux new-session -d -s "$s" -x 80 -y 24 \
	"env TERM=tmux-256color COLORTERM=truecolor HOME='$TMP' '$RTSH' -t 1 -m path '$TMP/m/a_model_with_a_long_name_indeed.obj'; exec sleep 60" ||
	fail "tmux"
wait_for "rtsh>" "no prompt"
tmux send-keys -t "$s" view Enter
wait_for " view │ " "no key-mode status line"
# the status line itself, once it shows samples (before: "rendering")
for i in $(seq 1 100); do
	line=$(screen | grep ' view │ ')
	case $line in *spp*) break ;; esac
	sleep 0.1
done
case $line in *"camera"*"spp"*"step "[0-9]*) ;; *) fail "the status line is cut: $line" ;; esac
w=$(printf '%s' "$line" | sed 's/ *$//' | wc -m)
[ "$w" -le 80 ] || fail "the status line is $w columns wide: $line"
tmux kill-server
echo ok
