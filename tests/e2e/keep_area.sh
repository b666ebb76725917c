#!/bin/sh
# The command area outlives a resize and Ctrl-Z/fg (issue 31, defect 11):
# the last commands, their output (the "rendered ... in N s" line too) and
# the prompt are on screen again afterwards, also a command's output that
# came just before a render stopped by Ctrl-Z.
set -u
s=rtsh-keep-$$
. tests/e2e/lib.sh
# kept WHAT: the area shows the commands and output of before, and a prompt.
kept() {
	for i in $(seq 1 50); do
		case $(screen) in *"object 1: sp 0,0,1 "*"rendered 64x36, 1 sample, whitted"*) break ;; esac
		sleep 0.1
	done
	case $(screen) in *"rtsh> render"*"rendered 64x36, 1 sample, whitted, depth 5 in "*" s"*) ;;
	*) fail "$1: the render's line is gone:
$(screen | tail -n 8)" ;;
	esac
	case $(screen) in *"object 1: sp 0,0,1 "*"rtsh> render"*) ;;
	*) fail "$1: the command before and its output are gone:
$(screen | tail -n 8)" ;;
	esac
	screen | tail -n 1 | grep -q '^rtsh> *$' || fail "$1: no prompt on the last row:
$(screen | tail -n 4)"
}
cat >"$TMP/s.rt" <<'SCENE'
A 0.3 255,255,255
C 0,0,-10 0,0,1 70
L -10,10,-10 0.7 255,255,255
sp 0,0,0 4 230,60,50
SCENE
tmux new-session -d -s "$s" -x 80 -y 30 \
	"env TERM=tmux-256color COLORTERM=truecolor HOME='$TMP' '$RTSH' -t 1 -r 64x36 '$TMP/s.rt'; echo rtsh-ended; exec sleep 60" ||
	fail "tmux"
wait_for "rtsh>" "no prompt"
pid=$(ps -o pid= --ppid "$(tmux display -p -t "$s" '#{pane_pid}')" | tr -d ' ')
[ -n "$pid" ] || fail "no rtsh process under the pane's shell"
tmux send-keys -t "$s" 'object 1 move 0,0,1' Enter
wait_for "object 1: sp 0,0,1 " "the move did not answer"
tmux send-keys -t "$s" 'render' Enter
wait_for "rendered 64x36" "render did not say rendered"
sleep 0.5
kept "before anything"
tmux resize-window -t "$s" -x 100 -y 36
sleep 1
kept "after a resize to 100x36"
tmux resize-window -t "$s" -x 80 -y 24
sleep 1
kept "after a resize to 80x24"
kill -s TSTP "$pid"
sleep 0.5
kill -s CONT "$pid"
sleep 1
kept "after Ctrl-Z and fg"
# A command typed but not run stays on the prompt line.
tmux send-keys -t "$s" 'list obj'
sleep 0.3
tmux resize-window -t "$s" -x 90 -y 28
sleep 1
screen | tail -n 1 | grep -q '^rtsh> list obj *$' || fail "the line being typed is gone after a resize:
$(screen | tail -n 4)"
tmux kill-session -t "$s"
echo ok
