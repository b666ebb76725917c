# Helpers for the rtsh-mpi tests (sourced by each *.test).
. tests/scripts/lib.sh
# mpi N ARGS...: rtsh-mpi on N ranks.
mpi() {
	n=$1; shift
	$MPIRUN -n "$n" "$RTSH_MPI" "$@"
}
# rank_pid N: the pid of rank N of the running rtsh-mpi job ('' if none yet).
rank_pid() {
	for p in $(pgrep -f "$RTSH_MPI"); do
		alive "$p" || continue
		if tr '\0' '\n' <"/proc/$p/environ" 2>/dev/null | grep -qx "OMPI_COMM_WORLD_RANK=$1"; then
			echo "$p"; return
		fi
	done
}
# alive PID: the process exists and is not a zombie (a container's init may
# never reap the ranks mpirun leaves behind).
alive() {
	[ -r "/proc/$1/stat" ] && ! sed 's/.*) //' "/proc/$1/stat" 2>/dev/null | grep -q '^Z'
}
# wait_gone PID SECONDS: true when the process has ended within the time.
wait_gone() {
	i=0
	while alive "$1"; do
		i=$((i + 1)); [ $i -gt $(($2 * 10)) ] && return 1
		sleep 0.1
	done
}
