# Helpers for the end-to-end tests under tmux (sourced by each after it sets
# $s, its session's name), as tests/scripts/lib.sh is for the command-file
# tests. A tmux server of the test's own (other tests' servers come and go),
# without the user's configuration.
sock=rtsh-e2e-$$
tmux() { command tmux -L "$sock" -f /dev/null "$@"; }
# fail MESSAGE: print it, end this test's tmux server and its sessions, exit 1.
fail() { echo "FAIL: $*"; tmux kill-server 2>/dev/null; exit 1; }
# screen: the pane as text.
screen() { tmux capture-pane -t "$s" -p; }
# wait_for TEXT WHY: up to 30 s for TEXT on the pane; else fail with WHY and
# the pane's last lines.
wait_for() {
	for i in $(seq 1 300); do
		case $(screen) in *"$1"*) return 0 ;; esac
		sleep 0.1
	done
	fail "$2; the screen ends with:
$(screen | grep -v '^ *$' | tail -n 6)"
}
