#!/bin/sh
# Truecolor inside tmux without COLORTERM (issue 31, friction 6): tmux (3.3a
# to 3.6b) answers no XTGETTCAP from a pane, but its client's terminal
# features say RGB when that terminal has truecolor (terminal-features
# ',xterm*:RGB', or found by asking: an outer tmux is known to have RGB).
# An attached tmux client (run in an outer tmux, so that it has a terminal):
# rtsh draws in 24-bit colour and shows no 256-colour notice. (A session
# with no client attached says no features: notice.sh checks that rtsh then
# says 256 colours.)
set -u
outer=rtsh-e2e-o-$$ inner=rtsh-e2e-i-$$
fail() { echo "FAIL: $*"; tmux -L "$inner" kill-server 2>/dev/null; tmux -L "$outer" kill-server 2>/dev/null; exit 1; }
run() { # run FEATURES: rtsh in an attached inner session; its pane's text with colours in $TMP/pane
	printf 'set -g terminal-features "%s"\n' "$1" >"$TMP/conf"
	tmux -L "$outer" -f /dev/null new-session -d -s o -x 100 -y 30 \
		"env -u TMUX -u COLORTERM TERM=xterm-256color tmux -L $inner -f $TMP/conf new-session -s i \"env -u COLORTERM HOME='$TMP' '$RTSH' -t 1 scenes/showcase.rt\"" ||
		fail "tmux"
	for i in $(seq 1 100); do
		tmux -L "$inner" capture-pane -p -t i 2>/dev/null | grep -q 'spp' && break
		sleep 0.1
	done
	sleep 1.5 # the start-up answers, a possible notice, the repaint
	tmux -L "$inner" capture-pane -p -e -t i >"$TMP/pane" 2>/dev/null || fail "no inner pane"
	tmux -L "$inner" kill-server 2>/dev/null
	tmux -L "$outer" kill-server 2>/dev/null
}
run ',xterm*:RGB'
grep -q '48;2;' "$TMP/pane" || fail "RGB in tmux's client features, but no 24-bit colour: $(tail -n 3 "$TMP/pane" | cat -v)"
grep -q '256 colours' "$TMP/pane" && fail "RGB in tmux's client features, and a 256-colour notice"
echo ok
