#!/bin/sh
# The whole test suite, as `make test` runs it: the unit tests and the
# command-file tests on the plain build, the end-to-end tmux test, the
# rtsh-mpi tests (skipped without mpirun), then the
# unit and command-file tests again under AddressSanitizer +
# UndefinedBehaviorSanitizer, and the threaded tests under ThreadSanitizer.
# Goes on after a failure; the last line is "N passed, N failed".
set -u
MAKE=${MAKE:-make}
results=build/test-results
rm -rf "$results"; mkdir -p "$results"
export RTSH_TEST_RESULTS="$PWD/$results"
status=0
step() { # name, command...
	name=$1; shift
	echo "=== $name"
	"$@" || status=1
}
step "build" $MAKE --no-print-directory -s all test-bins
step "unit tests" sh tests/run-unit.sh build build/tests/test_*
step "command-file tests" sh tests/run-scripts.sh ./rtsh
step "end-to-end (tmux)" sh tests/e2e/run.sh ./rtsh
step "link simulator" sh tests/link/run.sh ./rtsh build/tests/linksim
step "over sshd" sh tests/link/sshd.sh ./rtsh build/tests/linksim
step "rtsh-mpi (Open MPI)" sh tests/mpi/run.sh ./rtsh ./rtsh-mpi
step "build (ASan+UBSan)" $MAKE --no-print-directory -s BUILD=build/asan SAN=address,undefined OPT=-O1 build/asan/rtsh test-bins
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	step "unit tests (ASan+UBSan)" sh tests/run-unit.sh build/asan build/asan/tests/test_*
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	step "command-file tests (ASan+UBSan)" sh tests/run-scripts.sh build/asan/rtsh
step "build (TSan)" $MAKE --no-print-directory -s BUILD=build/tsan SAN=thread OPT=-O1 build/tsan/rtsh build/tsan/tests/test_render build/tsan/tests/test_render_service build/tsan/tests/test_keymode build/tsan/tests/test_denoise build/tsan/tests/test_evloop
TSAN_OPTIONS=halt_on_error=1 step "threaded tests (TSan)" sh tests/run-unit.sh build/tsan build/tsan/tests/test_render build/tsan/tests/test_render_service build/tsan/tests/test_keymode build/tsan/tests/test_denoise build/tsan/tests/test_evloop
# The libFuzzer targets (tests/fuzz), a few seconds each, when clang has libFuzzer.
if sh tests/fuzz/have-libfuzzer.sh; then
	step "build (libFuzzer)" $MAKE --no-print-directory -s fuzz-bins
	step "fuzz smoke (3 s a target)" sh tests/fuzz/run.sh build/fuzz 3
else
	echo "=== fuzz smoke: skipped (no clang with -fsanitize=fuzzer; apt-get install clang)"
fi
sh tests/summary.sh "$results" || status=1
exit $status
