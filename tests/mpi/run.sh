#!/bin/sh
# Runs the rtsh-mpi tests: each tests/mpi/*.test is a shell script run with
# $RTSH (the plain binary), $RTSH_MPI, $MPIRUN (mpirun with the options this
# machine needs) and $TMP (a fresh folder); it passes when it exits 0.
# Skipped, with a message, when mpirun or rtsh-mpi is absent.
set -u
rtsh=$1 mpi=$2
case $rtsh in /*) ;; *) rtsh="$PWD/$rtsh" ;; esac
case $mpi in /*) ;; *) mpi="$PWD/$mpi" ;; esac
results=${RTSH_TEST_RESULTS:-build/test-results}
mkdir -p "$results"
if ! command -v mpirun >/dev/null 2>&1 || [ ! -x "$mpi" ]; then
	echo "[ SKIPPED  ] rtsh-mpi tests: no mpirun or no $mpi (apt-get install openmpi-bin libopenmpi-dev)"
	exit 0
fi
# Open MPI refuses root without --allow-run-as-root and more ranks than
# cores without --oversubscribe; -q keeps its own banners out of stderr so
# the tests see rtsh-mpi's messages alone.
MPIRUN="mpirun -q"
if mpirun --version 2>/dev/null | grep -q "Open MPI"; then
	MPIRUN="$MPIRUN --oversubscribe"
	[ "$(id -u)" = 0 ] && MPIRUN="$MPIRUN --allow-run-as-root"
fi
export MPIRUN
passed=0 failed=0
for t in tests/mpi/*.test; do
	[ -f "$t" ] || continue
	tmp=$(mktemp -d)
	if out=$(RTSH="$rtsh" RTSH_MPI="$mpi" TMP="$tmp" sh "$t" 2>&1); then
		passed=$((passed + 1)); echo "[       OK ] $t"
	else
		failed=$((failed + 1)); echo "[  FAILED  ] $t"; echo "$out" | sed 's/^/    /'
	fi
	rm -rf "$tmp"
done
echo "[==========] rtsh-mpi tests with $mpi: $passed passed, $failed failed"
echo "$passed $failed" >"$results/mpi_$(echo "$mpi" | tr / _).count"
[ $failed = 0 ]
