#!/bin/sh
# `show` prints the picture of the scene as it is (issue: `show` after an
# edit on the same line printed the picture from before the edit, which
# was still on screen). A red sphere fills the view; `object 1 move
# 0,0,1000; show` moves it out of sight (the background is black, no sky):
# the page must hold no red cell, where the old picture was all red.
set -u
s=rtsh-show-$$
. tests/e2e/lib.sh
cat >"$TMP/s.rt" <<'SCENE'
A 0.3 255,255,255
C 0,0,-10 0,0,1 70
L -10,10,-10 0.7 255,255,255
sp 0,0,0 12 255,0,0
SCENE
tmux new-session -d -s "$s" -x 80 -y 30 \
	"env TERM=tmux-256color COLORTERM=truecolor HOME='$TMP' '$RTSH' -t 1 -m whitted -s 1 '$TMP/s.rt'; exec sleep 60" ||
	fail "tmux"
wait_for "1/1 spp" "no finished preview"
# red: a truecolor escape of red at least 100 and green and blue below 30
red() { tmux capture-pane -t "$s" -p -e | grep -oE '[34]8;2;(1[0-9][0-9]|2[0-9][0-9]);([0-2]?[0-9]);([0-2]?[0-9])m' | wc -l; }
n=$(red)
[ "$n" -gt 100 ] || fail "the sphere is not on screen before the move ($n red colours)"
tmux send-keys -t "$s" 'object 1 move 0,0,1000; show' Enter
wait_for "Space next page" "show was not paged"
sleep 0.5
n=$(red)
[ "$n" -eq 0 ] || fail "show printed the picture from before the move: $n red colours in the page"
tmux send-keys -t "$s" q
tmux send-keys -t "$s" 'quit!' Enter
tmux kill-server 2>/dev/null
echo ok
