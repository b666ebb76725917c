#!/bin/sh
# End-to-end tests under tmux: each tests/e2e/*.sh (but this one and lib.sh,
# the helpers) drives the real binary in a tmux session. Skipped with a message where tmux is missing.
set -u
rtsh=$1
case $rtsh in /*) ;; *) rtsh="$PWD/$rtsh" ;; esac
results=${RTSH_TEST_RESULTS:-build/test-results}
mkdir -p "$results"
if ! command -v tmux >/dev/null 2>&1; then
	echo "SKIPPED: tmux is not installed (apt-get install -y tmux); end-to-end tests not run"
	exit 0
fi
passed=0 failed=0
for t in tests/e2e/*.sh; do
	case $(basename "$t") in run.sh | lib.sh) continue ;; esac
	tmp=$(mktemp -d)
	if out=$(RTSH="$rtsh" TMP="$tmp" sh "$t" 2>&1); then
		passed=$((passed + 1)); echo "[       OK ] $t"
	else
		failed=$((failed + 1)); echo "[  FAILED  ] $t"; echo "$out" | sed 's/^/    /'
	fi
	rm -rf "$tmp"
done
echo "[==========] end-to-end tests: $passed passed, $failed failed"
echo "$passed $failed" >"$results/e2e.count"
[ $failed = 0 ]
