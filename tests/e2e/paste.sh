#!/bin/sh
# Bracketed paste under tmux (issue 31, defect 4): a paste of many command
# lines runs them one by one, as bash does, when Enter is pressed; each
# line is its own command (its own history entry, its own error), and the
# prompt comes back at the bottom of the command area.
set -u
s=rtsh-paste-$$
. tests/e2e/lib.sh
cat >"$TMP/s.rt" <<'SCENE'
A 0.3 255,255,255
C 0,0,-10 0,0,1 70
L -10,10,-10 0.7 255,255,255
sp 0,0,0 4 230,60,50
SCENE
tmux new-session -d -s "$s" -x 80 -y 24 \
	"env TERM=tmux-256color COLORTERM=truecolor HOME='$TMP' '$RTSH' -t 1 '$TMP/s.rt'; echo rtsh-ended; exec sleep 60" ||
	fail "tmux"
wait_for "rtsh>" "no prompt"
sleep 0.3
# A short paste: three commands, the second one wrong; the paste ends with
# a newline, as a copied block does. Enter runs it.
tmux send-keys -t "$s" -l "$(printf '\033[200~set depth 3\nobject 9 move 1,0,0\nset samples 2\n\033[201~')"
sleep 0.3
tmux send-keys -t "$s" Enter
wait_for "samples 2 (was" "the third line of the paste did not run"
screen | grep -q 'depth 3 (was' || fail "the first line of the paste did not run:
$(screen | tail -n 8)"
screen | grep -q '"9" is not an object number' || fail "the wrong line was not reported on its own:
$(screen | tail -n 8)"
screen | grep -q 'too many arguments' && fail "the paste ran as one command"
sleep 0.3
screen | tail -n 1 | grep -q '^rtsh> *$' || fail "no prompt on the last row after the paste:
$(screen | tail -n 4)"
# A long paste: 2000 moves, then a save. The output is longer than the
# command area: it comes in the pager; q gives the prompt back.
{
	printf '\033[200~'
	i=0
	while [ $i -lt 2000 ]; do
		printf 'object 1 move 0,0,1\n'
		i=$((i + 1))
	done
	printf "save %s/moved.rt\n" "$TMP"
	printf '\033[201~'
} >"$TMP/paste"
tmux load-buffer -b "rtsh-paste-$$" "$TMP/paste"
tmux paste-buffer -d -b "rtsh-paste-$$" -t "$s"
sleep 1
tmux send-keys -t "$s" Enter
for i in $(seq 1 600); do
	[ -s "$TMP/moved.rt" ] && break
	sleep 0.1
done
[ -s "$TMP/moved.rt" ] || fail "the long paste's last line (save) did not run:
$(screen | tail -n 6)"
grep -q '^sp 0,0,2000 ' "$TMP/moved.rt" || fail "2000 moves of 1 did not move the sphere to z=2000:
$(grep '^sp' "$TMP/moved.rt")"
wait_for "Space next page" "the long output was not paged"
tmux send-keys -t "$s" q
sleep 0.5
for i in $(seq 1 50); do
	screen | tail -n 1 | grep -q '^rtsh> *$' && break
	sleep 0.1
done
screen | tail -n 1 | grep -q '^rtsh> *$' || fail "no prompt after the long paste:
$(screen | tail -n 4)"
tmux send-keys -t "$s" 'quit!' Enter
sleep 0.5
n=$(grep -c '^object 1 move 0,0,1$' "$TMP/.rtsh_history")
[ "$n" -ge 1 ] || fail "the pasted lines are not in the history"
tmux kill-session -t "$s"
echo ok
