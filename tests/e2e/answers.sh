#!/bin/sh
# rtsh under tmux at 120x40 (issue 13): `render` shows its progress in the
# status line (percent, spp, time left, Mrays/s); `show` goes through the
# pager; a typo gets a suggestion; an edit answers with the element's line.
set -u
fail() { echo "FAIL: $*"; tmux kill-session -t "$s" 2>/dev/null; exit 1; }
s=rtsh-e2e-answers-$$
tmux new-session -d -s "$s" -x 120 -y 40 "env -i PATH=\"$PATH\" HOME=\"$TMP\" TERM=tmux-256color COLORTERM=truecolor sh" ||
	fail "tmux"
tmux send-keys -t "$s" "cd '$PWD' && '$RTSH' scenes/showcase.rt" Enter
screen=
for i in $(seq 1 100); do
	sleep 0.1
	screen=$(tmux capture-pane -t "$s" -p)
	case $screen in *"1/1 spp"*"rtsh>"*) break ;; esac
done
case $screen in *"1/1 spp"*) ;; *) fail "no finished preview:
$screen" ;; esac
# A typo gets a suggestion.
tmux send-keys -t "$s" 'lod x.rt' Enter
sleep 0.3
tmux capture-pane -t "$s" -p | grep -q 'unknown command "lod"; did you mean "load"?' ||
	fail "no suggestion for lod:
$(tmux capture-pane -t "$s" -p | tail -n 5)"
# An edit answers.
tmux send-keys -t "$s" 'object 3 move 0.5,0,0' Enter
sleep 0.3
tmux capture-pane -t "$s" -p | grep -q '^object 3: sp 0.5,1,0 2 225,45,40' || fail "no answer to the edit:
$(tmux capture-pane -t "$s" -p | tail -n 5)"
# Progress: a render long enough to be watched, stopped with Ctrl-C.
tmux send-keys -t "$s" 'set mode path; set resolution 640x360; set samples 512; render' Enter
seen=
for i in $(seq 1 100); do
	sleep 0.1
	st=$(tmux capture-pane -t "$s" -p | grep 'rendering 640x360' || true)
	case $st in *"%"*"/512 spp"*"left"*"Mrays/s"*) seen=1 && break ;; esac
done
[ -n "$seen" ] || fail "no progress in the status line:
$(tmux capture-pane -t "$s" -p | tail -n 12)"
pct1=$(echo "$st" | sed -n 's/.*] *\([0-9]*\)%.*/\1/p')
sleep 1
st2=$(tmux capture-pane -t "$s" -p | grep 'rendering 640x360' || true)
pct2=$(echo "$st2" | sed -n 's/.*] *\([0-9]*\)%.*/\1/p')
[ -n "$pct2" ] && [ "$pct2" -ge "$pct1" ] || fail "the progress did not move on: $st / $st2"
tmux send-keys -t "$s" C-c
stopped=
for i in $(seq 1 50); do
	sleep 0.1
	tmux capture-pane -t "$s" -p | grep -q 'render: stopped' && stopped=1 && break
done
[ -n "$stopped" ] || fail "Ctrl-C did not stop the render:
$(tmux capture-pane -t "$s" -p | tail -n 5)"
# show: the picture is taller than the command area, so it is paged.
tmux send-keys -t "$s" 'set mode whitted; set samples 1; show' Enter
paged=
for i in $(seq 1 50); do
	sleep 0.1
	tmux capture-pane -t "$s" -p | grep -q 'Space next page' && paged=1 && break
done
[ -n "$paged" ] || fail "show was not paged:
$(tmux capture-pane -t "$s" -p | tail -n 5)"
# the pager's page goes out through the paced scheduler: its title line can
# be on screen a moment before the picture rows under it
n=0
for i in $(seq 1 30); do
	n=$(tmux capture-pane -t "$s" -p | head -n 30 | grep -o '▀\|▄' | wc -l)
	[ "$n" -gt 1000 ] && break
	sleep 0.1
done
[ "$n" -gt 1000 ] || fail "the pager shows only $n half blocks after 3 s"
tmux send-keys -t "$s" q
sleep 0.5
tmux capture-pane -t "$s" -p | tail -n 2 | grep -q '^rtsh> *$' || fail "no prompt after the pager"
tmux send-keys -t "$s" 'quit' Enter
for i in $(seq 1 50); do
	sleep 0.1
	[ "$(tmux display -p -t "$s" '#{alternate_on}')" = 0 ] && break
done
tmux kill-session -t "$s"
echo "ok"
