#!/bin/sh
# Runs one libFuzzer target until its own process has used CPU_SECONDS of CPU
# (user + system time of all its threads, read from /proc/PID/stat), then
# stops it with SIGINT. On a shared machine an hour of wall time is not an hour
# of fuzzing; this counts the fuzzing itself.
#
#   sh tests/fuzz/campaign.sh BUILD NAME CPU_SECONDS
#
# BUILD is where `make fuzz-bins` put the targets (build/fuzz). The corpus
# grows in BUILD/corpus/NAME (the one tests/fuzz/run.sh uses) from the
# committed seeds; the log is BUILD/campaign-NAME.log; a crash is left in
# BUILD/crash-NAME-*. Prints one line of figures at the end (the columns of
# tests/fuzz/README.md) and exits 1 if the target found anything.
# NICE (environment, default 19) sets the target's priority.
set -u
[ $# = 3 ] || { echo "usage: sh tests/fuzz/campaign.sh BUILD NAME CPU_SECONDS" >&2; exit 2; }
build=$1 name=$2 budget=$3
case $build in /*) ;; *) build=$PWD/$build ;; esac
bin=$build/fuzz_$name
[ -x "$bin" ] || { echo "campaign: no $bin (make fuzz-bins)" >&2; exit 2; }
seeds=$PWD/tests/fuzz/corpus/$name
work=$build/corpus/$name
log=$build/campaign-$name.log
mkdir -p "$work" "$seeds"
export LSAN_OPTIONS="suppressions=$PWD/tests/fuzz/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
extra=$(cat "tests/fuzz/$name.options" 2>/dev/null)
tick=$(getconf CLK_TCK)

start=$(date +%s)
# shellcheck disable=SC2086
nice -n "${NICE:-19}" "$bin" -max_total_time=0 -timeout=25 -rss_limit_mb=2560 \
	-print_final_stats=1 -artifact_prefix="$build/crash-$name-" $extra \
	"$work" "$seeds" >"$log" 2>&1 &
pid=$!

# CPU seconds used so far by $pid (utime + stime: fields 14 and 15, counted
# after the ")" that ends the command name).
cpu_of() {
	sed 's/.*) //' "/proc/$1/stat" 2>/dev/null | awk -v t="$tick" '{ printf "%d", ($12 + $13) / t }'
}

cpu=0
while kill -0 "$pid" 2>/dev/null; do
	c=$(cpu_of "$pid")
	[ -n "$c" ] && cpu=$c
	if [ "$cpu" -ge "$budget" ]; then
		kill -INT "$pid"
		break
	fi
	sleep 10
done
wait "$pid"
rc=$?
wall=$(( $(date +%s) - start ))

runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | tail -1 | tr -dc 0-9)
last=$(grep -E '^#[0-9]+' "$log" | tail -1)
cov=$(printf '%s\n' "$last" | sed -n 's/.*cov: \([0-9]*\).*/\1/p')
ft=$(printf '%s\n' "$last" | sed -n 's/.*ft: \([0-9]*\).*/\1/p')
corp=$(printf '%s\n' "$last" | sed -n 's|.*corp: \([0-9]*\)/\([0-9A-Za-z]*\).*|\1 inputs, \2|p')
found=0
ls "$build"/crash-"$name"-* >/dev/null 2>&1 && found=1
grep -q 'ERROR: \|deadly signal\|Test unit written' "$log" && found=1
# libFuzzer ends with status 72 when interrupted (SIGINT), 0 at a time limit.
case $rc in 0|72) ;; *) found=1 ;; esac
printf '%s: wall %d s, CPU %d s (%.2f CPU-hours), %s runs, corpus %s, cov %s, ft %s, %s\n' \
	"fuzz_$name" "$wall" "$cpu" "$(awk -v c="$cpu" 'BEGIN { print c / 3600 }')" "${runs:-?}" "${corp:-?}" \
	"${cov:-?}" "${ft:-?}" "$([ $found = 0 ] && echo 'no crash' || echo "FOUND SOMETHING (status $rc; see $log)")"
exit $found
