#!/bin/sh
# Signals under tmux: at the prompt, during `render` and in `view` (key
# mode), every fatal signal (TERM HUP QUIT SEGV) leaves the terminal as it
# was before rtsh: main screen, cursor shown, keypad and cursor keys in
# normal mode (#{alternate_on} #{cursor_flag} #{keypad_flag}
# #{keypad_cursor_flag} = "0 1 0 0"). Ctrl-Z (SIGTSTP) gives the terminal
# back the same way and SIGCONT takes it again (alternate screen, and the
# keypad in key mode); SIGINT stops a render or leaves key mode without
# leaving a mode set. The pager comes back after Ctrl-Z and fg, and after a
# resize, on the text it showed.
set -u
s=rtsh-signals-$$
fail() { echo "FAIL: $*"; tmux kill-session -t "$s" 2>/dev/null; tmux kill-session -t "$s-keep" 2>/dev/null; exit 1; }
flags() { tmux display -p -t "$s" '#{alternate_on} #{cursor_flag} #{keypad_flag} #{keypad_cursor_flag}'; }
screen() { tmux capture-pane -t "$s" -p; }
# wait_for TEXT WHAT: up to 30 s for TEXT on the screen (a loaded machine).
wait_for() {
	for i in $(seq 1 300); do
		case $(screen) in *"$1"*) return 0 ;; esac
		sleep 0.1
	done
	fail "$2; the screen ends with:
$(screen | grep -v '^ *$' | tail -n 6)"
}
# wait_flags WANT WHAT: up to 5 s for the flags to read WANT.
wait_flags() {
	for i in $(seq 1 50); do
		[ "$(flags)" = "$1" ] && return 0
		sleep 0.1
	done
	fail "$2: the pane's flags are \"$(flags)\", expected \"$1\" (alternate cursor keypad keypad-cursor)"
}
dead() { case $(screen) in *rtsh-ended*) return 0 ;; esac; return 1; }
# wait_stopped WHAT: up to 5 s for rtsh ($pid) to be stopped.
wait_stopped() {
	for i in $(seq 1 50); do
		case $(ps -o stat= -p "$pid") in T*) return 0 ;; esac
		sleep 0.1
	done
	fail "$1: rtsh did not stop"
}

cat >"$TMP/s.rt" <<'EOF'
A 0.3 255,255,255
C 0,0,-10 0,0,1 70
L -10,10,-10 0.7 255,255,255
sp 0,0,0 4 230,60,50
pl 0,-2,0 0,1,0 200,200,200
EOF

# start CONTEXT: rtsh in a pane under a shell that outlives it (a dead
# pane's flags are tmux's own), brought to the prompt, into a long
# `render`, or into `view`.
start() {
	tmux new-session -d -s "$s" -x 100 -y 32 \
		"ulimit -c 0; env TERM=tmux-256color COLORTERM=truecolor HOME='$TMP' '$RTSH' -t 1 -s 64 '$TMP/s.rt'; echo rtsh-ended; exec sleep 60" ||
		fail "tmux"
	wait_for "rtsh>" "no prompt"
	pid=$(ps -o pid= --ppid "$(tmux display -p -t "$s" '#{pane_pid}')" | tr -d ' ')
	[ -n "$pid" ] || fail "no rtsh process under the pane's shell"
	case $1 in
	render)
		tmux send-keys -t "$s" 'set resolution 3000x2000; render' Enter
		wait_for "(Ctrl-C stops)" "the render did not start" ;;
	view)
		tmux send-keys -t "$s" 'view' Enter
		wait_for " view │" "key mode did not start"
		wait_flags "1 0 1 1" "key mode has no keypad mode" ;;
	esac
}

# A session that keeps the tmux server up between the test's own ones (a
# new session races with a server that is shutting down).
tmux new-session -d -s "$s-keep" "exec sleep 600" || fail "tmux"
for ctx in prompt render view; do
	for sig in TERM HUP QUIT SEGV; do
		start $ctx
		kill -s $sig "$pid"
		for i in $(seq 1 50); do dead && break; sleep 0.1; done
		dead || fail "SIG$sig in $ctx: rtsh is still running"
		wait_flags "0 1 0 0" "SIG$sig in $ctx"
		tmux kill-session -t "$s"
	done

	# Ctrl-Z and fg.
	start $ctx
	kill -s TSTP "$pid"
	wait_stopped "SIGTSTP in $ctx"
	wait_flags "0 1 0 0" "SIGTSTP in $ctx"
	kill -s CONT "$pid"
	if [ $ctx = view ]; then
		wait_flags "1 0 1 1" "SIGCONT in view"
		wait_for " view │" "SIGCONT in view: key mode is not drawn again"
	else
		for i in $(seq 1 50); do
			[ "$(tmux display -p -t "$s" '#{alternate_on}')" = 1 ] && break
			sleep 0.1
		done
		[ "$(tmux display -p -t "$s" '#{alternate_on}')" = 1 ] || fail "SIGCONT in $ctx: not on the alternate screen"
		if [ $ctx = render ]; then
			wait_for "(Ctrl-C stops)" "SIGCONT in render: no progress in the status line"
		else
			wait_for "rtsh>" "SIGCONT at the prompt: no prompt"
		fi
	fi

	# Ctrl-C: stops the render or leaves key mode; rtsh goes on.
	kill -s INT "$pid"
	sleep 0.5
	dead && fail "SIGINT in $ctx ended rtsh"
	wait_flags "1 1 0 0" "SIGINT in $ctx (after a stop and a continue)"
	tmux send-keys -t "$s" 'quit' Enter
	for i in $(seq 1 50); do dead && break; sleep 0.1; done
	dead || fail "quit after $ctx: rtsh is still running"
	wait_flags "0 1 0 0" "quit after $ctx"
	tmux kill-session -t "$s"
done
# The pager (`help`): Ctrl-Z and fg bring it back on the page it showed, and
# a new window size wraps it again from the same place (not the top).
start prompt
tmux send-keys -t "$s" 'help' Enter
wait_for "q quit" "help did not open the pager"
sleep 0.5
top=$(screen | head -n 1 | cut -c1-20)
tmux send-keys -t "$s" ' '
sleep 0.5
first=$(screen | head -n 1 | cut -c1-20)
[ "$first" != "$top" ] || fail "Space in the pager did not turn the page"
kill -s TSTP "$pid"
wait_stopped "SIGTSTP in the pager"
kill -s CONT "$pid"
wait_for "q quit" "SIGCONT in the pager: the pager is not shown again"
[ "$(screen | head -n 1 | cut -c1-20)" = "$first" ] ||
	fail "SIGCONT in the pager: it starts at \"$(screen | head -n 1 | cut -c1-20)\", not \"$first\""
tmux resize-window -t "$s" -x 70 -y 24
sleep 1
wait_for "q quit" "a new window size in the pager: the pager is not shown again"
# wrapped for 70 columns, the row that holds the same text: not the top
[ "$(screen | head -n 1 | cut -c1-20)" != "$top" ] || fail "a new window size in the pager: back at the top"
tmux send-keys -t "$s" q
wait_for "rtsh>" "no prompt after the pager"
tmux send-keys -t "$s" 'quit' Enter
for i in $(seq 1 50); do dead && break; sleep 0.1; done
dead || fail "quit after the pager: rtsh is still running"
tmux kill-session -t "$s"
tmux kill-session -t "$s-keep"
echo "ok"
