#!/bin/sh
# rtsh under tmux at 160x48 with a truecolor terminal: the picture (24-bit
# half blocks), the status line and the prompt appear; an edit changes the
# picture while the prompt stays; quit leaves the alternate screen.
set -u
fail() { echo "FAIL: $*"; tmux kill-session -t "$s" 2>/dev/null; exit 1; }
s=rtsh-e2e-$$
esc=$(printf '\033')
# A plain shell in the pane, so that the pane outlives rtsh.
tmux new-session -d -s "$s" -x 160 -y 48 "env -i PATH=\"$PATH\" HOME=\"$TMP\" TERM=tmux-256color COLORTERM=truecolor sh" ||
	fail "tmux"
tmux send-keys -t "$s" "cd '$PWD' && '$RTSH' scenes/showcase.rt" Enter
# Wait (up to 10 s) for the status line to show a finished preview.
screen=
for i in $(seq 1 100); do
	sleep 0.1
	screen=$(tmux capture-pane -t "$s" -p -e)
	case $screen in *"1/1 spp"*"rtsh>"*) break ;; esac
done
case $screen in *"1/1 spp"*) ;; *) fail "no finished preview in the status line:
$(tmux capture-pane -t "$s" -p)" ;; esac
sleep 0.3
screen=$(tmux capture-pane -t "$s" -p -e)
[ "$(tmux display -p -t "$s" '#{alternate_on}')" = 1 ] || fail "not on the alternate screen"
echo "$screen" | grep -q "$esc\[38;2;[0-9]*;[0-9]*;[0-9]*" || fail "no 24-bit colour on the screen"
n=$(echo "$screen" | grep -o '▀\|▄' | wc -l)
[ "$n" -gt 1000 ] || fail "only $n half blocks on the screen"
tmux capture-pane -t "$s" -p | tail -n 12 | grep -q "^rtsh>" || fail "no prompt"
before=$(tmux capture-pane -t "$s" -p -e | head -n 30)
tmux send-keys -t "$s" 'object 3 move 1,0,0' Enter
changed=
for i in $(seq 1 50); do
	sleep 0.1
	after=$(tmux capture-pane -t "$s" -p -e | head -n 30)
	[ "$after" != "$before" ] && changed=1 && break
done
[ -n "$changed" ] || fail "the picture did not change after object 3 move 1,0,0"
sleep 0.5
tmux capture-pane -t "$s" -p | tail -n 3 | grep -q '^rtsh> *$' || fail "the prompt is gone after the edit:
$(tmux capture-pane -t "$s" -p | tail -n 5)"
# Typing works while the picture updates; Ctrl-C clears the line.
tmux send-keys -t "$s" 'list obj' C-c
sleep 0.3
tmux capture-pane -t "$s" -p | tail -n 2 | grep -q '^rtsh> *$' || fail "Ctrl-C did not clear the line"
# A bad command is reported; the shell goes on.
tmux send-keys -t "$s" 'object 99 move 1,0,0' Enter
sleep 0.3
tmux capture-pane -t "$s" -p | grep -q 'object: "99" is not an object number' || fail "no error message"
# Output longer than the command area (help: about 25 lines, the area about
# 10) comes in a pager over the whole screen; q gives the picture back.
tmux send-keys -t "$s" 'help' Enter
paged=
for i in $(seq 1 30); do
	sleep 0.1
	tmux capture-pane -t "$s" -p | grep -q 'Space next page' && paged=1 && break
done
[ -n "$paged" ] || fail "help was not paged:
$(tmux capture-pane -t "$s" -p | tail -n 5)"
tmux capture-pane -t "$s" -p | head -n 1 | grep -q '^commands (a unique prefix' || fail "the pager does not start at the first line"
tmux capture-pane -t "$s" -p | grep -q '^  quit ' || fail "the pager does not show the whole help"
tmux send-keys -t "$s" q
back=
for i in $(seq 1 50); do
	sleep 0.1
	screen=$(tmux capture-pane -t "$s" -p -e)
	n=$(echo "$screen" | grep -o '▀\|▄' | wc -l)
	[ "$n" -gt 1000 ] && back=1 && break
done
[ -n "$back" ] || fail "the picture did not come back after the pager"
tmux capture-pane -t "$s" -p | tail -n 2 | grep -q '^rtsh> *$' || fail "no prompt after the pager"
# The scene was edited and not saved: quit asks once, a second quit leaves.
tmux send-keys -t "$s" 'quit' Enter
sleep 0.5
tmux capture-pane -t "$s" -p | grep -q 'edits not saved' || fail "quit after an edit did not ask"
tmux send-keys -t "$s" 'quit' Enter
for i in $(seq 1 50); do
	sleep 0.1
	[ "$(tmux display -p -t "$s" '#{alternate_on}')" = 0 ] && break
done
[ "$(tmux display -p -t "$s" '#{alternate_on}')" = 0 ] || fail "the alternate screen was not left"
[ -s "$TMP/.rtsh_history" ] || fail "no history file in \$HOME"
grep -q 'object 3 move 1,0,0' "$TMP/.rtsh_history" || fail "the history misses the command"
tmux kill-session -t "$s"
echo "ok"
