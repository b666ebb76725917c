#!/bin/sh
# Runs every libFuzzer target of tests/fuzz for a number of seconds each:
#   sh tests/fuzz/run.sh BUILD SECONDS
# Each target starts from its committed seed corpus (tests/fuzz/corpus/NAME)
# and keeps what it finds in BUILD/corpus/NAME; a crash is saved as
# BUILD/crash-NAME-* (replay: BUILD/fuzz_NAME FILE). Records each target's
# result in $RTSH_TEST_RESULTS when set (make test's summary).
set -u
build=$1 seconds=$2
case $build in /*) ;; *) build=$PWD/$build ;; esac
results=${RTSH_TEST_RESULTS:-}
# a leak inside libXpm on malformed XPM files (lsan.supp says which)
export LSAN_OPTIONS="suppressions=$PWD/tests/fuzz/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
status=0
for src in tests/fuzz/fuzz_*.c; do
	name=$(basename "$src" .c); name=${name#fuzz_}
	bin=$build/fuzz_$name
	seeds=$PWD/tests/fuzz/corpus/$name
	work=$build/corpus/$name
	mkdir -p "$work" "$seeds"
	log=$build/fuzz_$name.log
	# Flags: fuzz.options holds the target's own (dictionary, limits).
	extra=$(cat "tests/fuzz/$name.options" 2>/dev/null)
	"$bin" -max_total_time="$seconds" -timeout=25 -rss_limit_mb=2560 -print_final_stats=1 \
		-artifact_prefix="$build/crash-$name-" $extra "$work" "$seeds" >"$log" 2>&1
	rc=$?
	runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | tr -dc 0-9)
	if [ $rc = 0 ]; then
		echo "[       OK ] fuzz $name: ${runs:-?} runs in ${seconds} s, corpus $(ls "$work" | wc -l) + $(ls "$seeds" | wc -l) seeds"
		[ -n "$results" ] && echo "1 0" >"$results/fuzz_$name.count"
	else
		status=1
		echo "[  FAILED  ] fuzz $name (status $rc); the input is in $build/crash-$name-*; log $log:"
		grep -A30 -m1 'ERROR\|==ERROR\|round trip\|deadly signal' "$log" | head -40 | sed 's/^/    /'
		[ -n "$results" ] && echo "0 1" >"$results/fuzz_$name.count"
	fi
done
exit $status
