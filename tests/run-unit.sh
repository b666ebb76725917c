#!/bin/sh
# Runs cmocka test binaries: run-unit.sh BUILD BIN...; records each binary's
# counts in $RTSH_TEST_RESULTS for the summary.
set -u
build=$1; shift
results=${RTSH_TEST_RESULTS:-$build/test-results}
mkdir -p "$results"
# The end-to-end unit tests run the rtsh binary of the same build.
if [ "$build" = build ]; then RTSH_BIN=./rtsh; else RTSH_BIN=$build/rtsh; fi
export RTSH_BIN
status=0
for t in "$@"; do
	[ -x "$t" ] || continue
	log=$(mktemp)
	"$t" >"$log" 2>&1; rc=$?
	cat "$log"
	# cmocka writes to both stdout and stderr, so a count may share a line.
	passed=$(grep -o '\[  PASSED  \] [0-9]* test' "$log" | tail -n 1 | tr -dc 0-9)
	failed=$(grep -o '\[  FAILED  \] [0-9]* test' "$log" | tail -n 1 | tr -dc 0-9)
	passed=${passed:-0}; failed=${failed:-0}
	if [ $rc -ne 0 ] && [ "$failed" = 0 ]; then
		failed=1 # crashed or a sanitizer stopped it
		echo "$t: exited with status $rc"
	fi
	[ $rc -ne 0 ] && status=1
	echo "$passed $failed" >"$results/$(echo "$build/$(basename "$t")" | tr / _).count"
	rm -f "$log"
done
exit $status
