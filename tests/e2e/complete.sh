#!/bin/sh
# Tab completion as a person sees it (issue 31, defect 10): a folder with a
# space is inserted quoted, so that the command then works; `save out` Tab
# shows what it can write (out.png, out.rt, ...), not just "out.".
set -u
s=rtsh-complete-$$
. tests/e2e/lib.sh
mkdir -p "$TMP/my scenes"
cat >"$TMP/my scenes/one.rt" <<'SCENE'
A 0.3 255,255,255
C 0,0,-10 0,0,1 70
L -10,10,-10 0.7 255,255,255
sp 0,0,0 4 230,60,50
SCENE
tmux new-session -d -s "$s" -x 100 -y 40 \
	"cd '$TMP' && env TERM=tmux-256color COLORTERM=truecolor HOME='$TMP' '$RTSH' -t 1 'my scenes/one.rt'; echo rtsh-ended; exec sleep 60" ||
	fail "tmux"
wait_for "rtsh>" "no prompt"
sleep 0.3
tmux send-keys -t "$s" 'load my' Tab
sleep 0.5
screen | tail -n 1 | grep -q "^rtsh> load 'my scenes/ *\$\|^rtsh> load my\\\\ scenes/ *\$" ||
	fail "load my<Tab> did not give the folder quoted:
$(screen | tail -n 2)"
tmux send-keys -t "$s" 'o' Tab
sleep 0.5
tmux send-keys -t "$s" Enter
wait_for "loaded" "the completed name did not load:"
screen | grep -q 'loaded my scenes/one.rt' || fail "loaded something else:
$(screen | tail -n 4)"
tmux send-keys -t "$s" 'save out' Tab
sleep 0.5
case $(screen) in *out.png*out.rt*|*out.rt*out.png*) ;; *) fail "save out<Tab> did not show out.png and out.rt:
$(screen | tail -n 4)" ;; esac
tmux kill-server
echo ok
