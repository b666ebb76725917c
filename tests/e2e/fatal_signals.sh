#!/bin/sh
# Every fatal signal leaves the terminal as it was (issue 14): rtsh runs in a
# tmux pane under a shell that saves `stty -g` and the pane's mode flags
# before it starts and compares them after it ends. In the shell (at the
# prompt), in the pager (`help`) and in key mode (`view`), each of SIGSEGV,
# SIGABRT, SIGBUS, SIGFPE (the crash handler), SIGTERM, SIGHUP (the loops'
# orderly end), SIGUSR1 and SIGALRM (default-fatal signals rtsh has no use
# for) ends rtsh with status 128 + the signal, and leaves the terminal's
# modes (stty -g) and the pane's flags (main screen, cursor shown, keypad and
# cursor keys normal, no mouse reporting, insert/origin/wrap as before) as
# they were. The bytes rtsh wrote (tmux pipe-pane) end every private mode
# it set (alternate screen, bracketed paste, synchronized output, cursor
# keys, mouse...; tmux has no flag for some of them): the last of each
# \e[?N h / l is l, but for the cursor (25) and autowrap (7), on by default,
# whose last is h; the keypad's last is \e> when \e= came. SIGINT leaves
# the pager or key mode (rtsh goes on); after it, `quit` leaves them as they
# were too.
set -u
s=rtsh-fatal-$$
. tests/e2e/lib.sh
F='#{alternate_on} #{cursor_flag} #{keypad_flag} #{keypad_cursor_flag} #{mouse_any_flag} #{mouse_button_flag} #{mouse_standard_flag} #{mouse_sgr_flag} #{mouse_all_flag} #{mouse_utf8_flag} #{insert_flag} #{origin_flag} #{wrap_flag}'
flags() { tmux display -p -t "$s" "$F"; }

cat >"$TMP/s.rt" <<'E'
A 0.3 255,255,255
C 0,0,-10 0,0,1 70
L -10,10,-10 0.7 255,255,255
sp 0,0,0 4 230,60,50
pl 0,-2,0 0,1,0 200,200,200
E
# The pane: save the modes, wait for a key, run rtsh, save its status and
# the modes again.
cat >"$TMP/pane.sh" <<E
ulimit -c 0
stty -g >"$TMP/before"
printf 'ready\n'
read x
env TERM=tmux-256color COLORTERM=truecolor HOME='$TMP' '$RTSH' -t 1 -s 16 '$TMP/s.rt'
echo \$? >"$TMP/status"
stty -g >"$TMP/after"
echo rtsh-ended
exec sleep 60
E

start() {
	rm -f "$TMP/before" "$TMP/after" "$TMP/status" "$TMP/out.bytes"
	tmux new-session -d -s "$s" -x 100 -y 32 "sh '$TMP/pane.sh'" || fail "tmux"
	wait_for ready "the pane's shell did not start"
	tmux pipe-pane -t "$s" -o "cat >>'$TMP/out.bytes'" || fail "tmux pipe-pane"
	before_flags=$(flags)
	tmux send-keys -t "$s" Enter
	wait_for "rtsh>" "no prompt"
	pid=$(pgrep -P "$(tmux display -p -t "$s" '#{pane_pid}')" -x rtsh)
	[ -n "$pid" ] || fail "no rtsh process under the pane's shell"
	case $1 in
	pager)
		tmux send-keys -t "$s" 'help' Enter
		wait_for "Space next page" "help was not paged" ;;
	view)
		tmux send-keys -t "$s" 'view' Enter
		wait_for " view │" "key mode did not start"
		for i in $(seq 1 50); do
			[ "$(tmux display -p -t "$s" '#{keypad_flag}')" = 1 ] && break
			sleep 0.1
		done ;;
	esac
}

# ended WHAT STATUS: rtsh ended with STATUS; the modes and flags are back.
ended() {
	for i in $(seq 1 100); do [ -s "$TMP/after" ] && break; sleep 0.1; done
	[ -s "$TMP/after" ] || fail "$1: rtsh is still running"
	st=$(cat "$TMP/status")
	[ "$st" = "$2" ] || fail "$1: exit status $st, expected $2"
	cmp -s "$TMP/before" "$TMP/after" || fail "$1: the terminal's modes changed:
before $(cat "$TMP/before")
after  $(cat "$TMP/after")"
	after_flags=$(flags)
	[ "$after_flags" = "$before_flags" ] || fail "$1: the pane's flags are \"$after_flags\", expected \"$before_flags\" ($F)"
	sleep 0.2
	left=$(modes_left "$TMP/out.bytes")
	[ -z "$left" ] || fail "$1: rtsh's output leaves these modes set: $left"
	tmux kill-session -t "$s"
}

# modes_left FILE: the private modes whose last setting in FILE is not the
# default (see above), and "keypad" when the keypad was left in
# application mode.
esc=$(printf '\033')
modes_left() {
	grep -ao "$esc\[?[0-9;]*[hl]\|$esc[=>]" "$1" | tr -d "$esc" | awk '
		/^[=>]$/ { keypad = $0; next }
		{ c = substr($0, length($0)); n = split(substr($0, 3, length($0) - 3), m, ";")
		  for (i = 1; i <= n; i++) last[m[i]] = c }
		END { for (k in last) if ((k == 25 || k == 7) ? last[k] != "h" : last[k] != "l") printf "?%s%s ", k, last[k]
		      if (keypad == "=") printf "keypad" }'
}

# signum NAME: the signal's number (dash's kill -l gives names from numbers).
signum() { for n in $(seq 1 31); do [ "$(kill -l $n)" = "$1" ] && echo $n && return; done; fail "no signal $1"; }

tmux new-session -d -s "$s-keep" "exec sleep 600" || fail "tmux"
for ctx in shell pager view; do
	for sig in SEGV ABRT BUS FPE TERM HUP USR1 ALRM; do
		start $ctx
		kill -s $sig "$pid"
		ended "SIG$sig in $ctx" $((128 + $(signum $sig)))
	done
	start $ctx
	kill -s INT "$pid"
	sleep 0.5
	[ -s "$TMP/after" ] && fail "SIGINT in $ctx ended rtsh"
	wait_for "rtsh>" "SIGINT in $ctx: no prompt"
	tmux send-keys -t "$s" 'quit' Enter
	ended "SIGINT in $ctx, then quit" 0
done
tmux kill-session -t "$s-keep"
echo ok
