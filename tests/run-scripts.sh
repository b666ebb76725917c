#!/bin/sh
# Runs the command-file tests: each tests/scripts/*.test is a shell script
# run with $RTSH set to the binary under test and $TMP to a fresh folder; it
# passes when it exits 0. Prints one line per test.
set -u
rtsh=$1
case $rtsh in /*) ;; *) rtsh="$PWD/$rtsh" ;; esac
results=${RTSH_TEST_RESULTS:-build/test-results}
mkdir -p "$results"
passed=0 failed=0
for t in tests/scripts/*.test; do
	[ -f "$t" ] || continue
	tmp=$(mktemp -d)
	if out=$(RTSH="$rtsh" TMP="$tmp" sh "$t" 2>&1); then
		passed=$((passed + 1)); echo "[       OK ] $t"
	else
		failed=$((failed + 1)); echo "[  FAILED  ] $t"; echo "$out" | sed 's/^/    /'
	fi
	rm -rf "$tmp"
done
echo "[==========] command-file tests with $rtsh: $passed passed, $failed failed"
echo "$passed $failed" >"$results/scripts_$(echo "$rtsh" | tr / _).count"
[ $failed = 0 ]
