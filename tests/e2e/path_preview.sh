#!/bin/sh
# Path mode refines to a target of its own when nothing chose the samples
# (issue 31, friction 1): the showcase (1 sample) in path mode goes past
# 1/1 spp, and the status line says the target is the preview's own; a
# scene or `set samples` that chose them keeps its target. Key mode's
# refinement when keys stop goes to the same target.
set -u
sock=rtsh-e2e-$$
tmux() { command tmux -L "$sock" -f /dev/null "$@"; }
s=rtsh-path-$$
fail() { echo "FAIL: $*"; tmux kill-server 2>/dev/null; exit 1; }
screen() { tmux capture-pane -t "$s" -p; }
tmux new-session -d -s "$s" -x 100 -y 30 \
	"env TERM=tmux-256color COLORTERM=truecolor HOME='$TMP' '$RTSH' -t 2 scenes/showcase.rt; exec sleep 60" || fail "tmux"
for i in $(seq 1 100); do
	case $(screen) in *"rtsh>"*) break ;; esac
	sleep 0.1
done
tmux send-keys -t "$s" 'set mode path' Enter
more=
for i in $(seq 1 300); do
	line=$(screen | grep ' path │ ') && case $line in *" "[2-9]"/64 spp"*|*" "[1-6][0-9]"/64 spp"*) more=1; break ;; esac
	sleep 0.1
done
[ -n "$more" ] || fail "path mode did not refine past 1 sample: $(screen | grep '│' | tail -n 1)"
case $line in *"preview's own"*) ;; *) fail "the status line does not say whose target: $line" ;; esac
# Key mode refines to the same target when the keys stop (it stayed at
# 1/1 spp before).
tmux send-keys -t "$s" 'view' Enter
more=
for i in $(seq 1 300); do
	line=$(screen | grep '^ *view │') && case $line in *" "[2-9]"/64 spp"*|*" "[1-6][0-9]"/64 spp"*) more=1; break ;; esac
	sleep 0.1
done
[ -n "$more" ] || fail "key mode did not refine past 1 sample: $(screen | grep 'view │' | tail -n 1)"
tmux send-keys -t "$s" Escape
for i in $(seq 1 100); do
	case $(screen) in *"rtsh>"*) break ;; esac
	sleep 0.1
done
tmux send-keys -t "$s" 'set samples 4' Enter
for i in $(seq 1 100); do
	line=$(screen | grep ' path │ ') && case $line in *"/4 spp"*) break ;; esac
	sleep 0.1
done
case $line in *"/4 spp"*) ;; *) fail "set samples 4 is not the target: $line" ;; esac
case $line in *"preview's own"*) fail "set samples 4 is called the preview's own: $line" ;; esac
tmux kill-server
echo ok
