#!/bin/sh
# rtsh-mpi rows of `make bench`: the same image by rtsh (2 threads) and by
# rtsh-mpi on 1 rank x 2 threads, 2 ranks x 1 thread and 4 ranks x 1 thread
# (oversubscribed on a 2-core machine), runs interleaved, medians.
#   sh bench/mpi.sh [--runs N] [--out FILE.tsv] [--quick]
#   sh bench/mpi.sh --model [--runs N]   the delay experiment of bench/README.md
# "wall" is the whole command (mpirun start-up included); "render" is
# rtsh-mpi's own figure from -v (broadcast, tiles, assembly; no start-up,
# no file write). Skipped with a message when mpirun or ./rtsh-mpi is absent.
set -u
runs=3 out=build/bench-mpi.tsv quick=0 model=0
while [ $# -gt 0 ]; do
	case $1 in
	--runs) runs=$2; shift ;;
	--out) out=$2; shift ;;
	--quick) quick=1; runs=1 ;;
	--model) model=1 ;;
	*) echo "usage: bench/mpi.sh [--runs N] [--out FILE.tsv] [--quick] [--model]" >&2; exit 2 ;;
	esac
	shift
done
if ! command -v mpirun >/dev/null 2>&1 || [ ! -x ./rtsh-mpi ]; then
	echo "bench: no mpirun or no ./rtsh-mpi, so no rtsh-mpi rows (apt-get install openmpi-bin libopenmpi-dev; make mpi)"
	exit 0
fi
MPIRUN="mpirun -q"
if mpirun --version 2>/dev/null | grep -q "Open MPI"; then
	MPIRUN="$MPIRUN --oversubscribe --bind-to none"
	[ "$(id -u)" = 0 ] && MPIRUN="$MPIRUN --allow-run-as-root"
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT INT TERM

now() { date +%s.%N; }
median() { sort -g | awk '{v[NR]=$1} END {if (NR == 0) print "nan"; else if (NR % 2) print v[(NR+1)/2]; else print (v[NR/2]+v[NR/2+1])/2}'; }

# run KEY COMMAND...: one timed run; appends "wall render tiles1 secs1 busy1"
# to $tmp/KEY (the last three: rank 1's row of -v, when there is one).
run() {
	key=$1; shift
	t0=$(now)
	"$@" >"$tmp/log" 2>&1 || { echo "bench: failed: $*" >&2; cat "$tmp/log" >&2; return 1; }
	t1=$(now)
	render=$(sed -n 's/^all .* tiles of [0-9x]*, \([0-9.]*\) s,.*/\1/p' "$tmp/log")
	r1=$(awk '/^1 /{sub("%", "", $6); print $4, $5, $6}' "$tmp/log")
	echo "$(echo "$t1 - $t0" | bc) ${render:-nan} ${r1:-nan nan nan}" >>"$tmp/$key"
	cp "$tmp/log" "$tmp/$key.log"
}

if [ $model = 1 ]; then
	# A fixed delay added to every tile (each finished tile waits DELAY
	# before it is sent, so the rank's next tile comes DELAY later), for
	# several prefetch depths p: 2 ranks x 1 thread (T = 1), final.rt
	# 640x360, path, 4 samples, tiles of 32x32. Rank 1's busy share is the
	# measured efficiency; the model is min(1, (T + p) t / (T (t + L))), t
	# the measured time a tile, L the delay (or the measured round trip).
	printf 'delay_ms\tprefetch\truns\trank1_tiles\ttile_ms\tbusy_measured\tbusy_model\n'
	for delay in 0 10000 30000 100000; do
		for pf in 0 1 2 4; do
			for r in $(seq "$runs"); do
				RTSH_MPI_TILE=32 RTSH_MPI_DELAY_US=$delay RTSH_MPI_PREFETCH=$pf run "d$delay-p$pf" \
					$MPIRUN -n 2 ./rtsh-mpi scenes/final.rt -q -v -t 1 -r 640x360 -s 4 -o "$tmp/m.ppm" || exit 1
			done
			f="$tmp/d$delay-p$pf"
			tiles=$(cut -d' ' -f3 "$f" | median)
			secs=$(cut -d' ' -f4 "$f" | median)
			busy=$(cut -d' ' -f5 "$f" | median)
			rtt=$(awk '/^1 /{print $9}' "$f.log")
			awk -v d="$delay" -v p="$pf" -v n="$runs" -v tiles="$tiles" -v secs="$secs" -v busy="$busy" -v rtt="$rtt" 'BEGIN {
				t = secs * busy / 100 / tiles; L = (rtt > d ? rtt : d) / 1e6
				m = (1 + p) * t / (t + L); if (m > 1) m = 1
				printf "%g\t%d\t%d\t%d\t%.1f\t%.0f%%\t%.0f%%\n", d / 1000, p, n, tiles, t * 1000, busy, m * 100 }'
		done
	done
	exit 0
fi

if [ $quick = 1 ]; then
	sets="grid|scenes/grid.rt|-r,480x270 final|scenes/final.rt|-r,480x270,-s,1"
else
	sets="grid|scenes/grid.rt|-r,1920x1080 final|scenes/final.rt|-r,1920x1080,-s,4"
fi
mkdir -p "$(dirname "$out")"
printf 'scene\tmode\tresolution\tsamples\tranks\tthreads\truns\twall_s\trender_s\tvs_1x2\tnote\n' >"$out"
echo "rtsh-mpi rows (load $(cut -d' ' -f1-3 /proc/loadavg)); wall = whole command, render = rtsh-mpi's own -v figure"
printf '%-8s %-10s %5s %7s %5s %8s %8s  %s\n' scene resolution ranks threads runs wall_s render_s "render vs 1x2"
for set in $sets; do
	name=${set%%|*}; rest=${set#*|}; scene=${rest%%|*}; args=$(echo "${rest#*|}" | tr , ' ')
	rm -f "$tmp"/rtsh "$tmp"/mpi*
	for r in $(seq "$runs"); do
		# rotate the order so that no configuration always runs first
		for k in $(echo "rtsh mpi1x2 mpi2x1 mpi4x1 rtsh mpi1x2 mpi2x1" | cut -d' ' -f$((r % 4 + 1))-$((r % 4 + 4))); do
			case $k in
			rtsh) run rtsh ./rtsh "$scene" -q -t 2 $args -o "$tmp/a.ppm" ;;
			mpi1x2) run mpi1x2 $MPIRUN -n 1 ./rtsh-mpi "$scene" -q -v -t 2 $args -o "$tmp/b.ppm" ;;
			mpi2x1) run mpi2x1 $MPIRUN -n 2 ./rtsh-mpi "$scene" -q -v -t 1 $args -o "$tmp/c.ppm" ;;
			mpi4x1) run mpi4x1 $MPIRUN -n 4 ./rtsh-mpi "$scene" -q -v -t 1 $args -o "$tmp/d.ppm" ;;
			esac || exit 1
		done
	done
	cmp -s "$tmp/a.ppm" "$tmp/c.ppm" && cmp -s "$tmp/a.ppm" "$tmp/d.ppm" ||
		{ echo "bench: rtsh-mpi's image differs from rtsh's ($scene $args)" >&2; exit 1; }
	base=$(cut -d' ' -f2 "$tmp/mpi1x2" | median)
	res=$(echo "$args" | sed -n 's/.*-r \([0-9x]*\).*/\1/p')
	spp=$(echo "$args" | sed -n 's/.*-s \([0-9]*\).*/\1/p')
	mode=whitted
	grep -q '^set mode path' "$scene" && mode=path
	for k in rtsh mpi1x2 mpi2x1 mpi4x1; do
		wall=$(cut -d' ' -f1 "$tmp/$k" | median)
		render=$(cut -d' ' -f2 "$tmp/$k" | median)
		case $k in
		rtsh) ranks=- threads=2 note="rtsh, the same image" ;;
		mpi1x2) ranks=1 threads=2 note="rtsh-mpi" ;;
		mpi2x1) ranks=2 threads=1 note="rtsh-mpi; bytes equal to rtsh's" ;;
		mpi4x1) ranks=4 threads=1 note="rtsh-mpi, 4 processes on 2 cores" ;;
		esac
		ratio=-
		[ "$render" != nan ] && ratio=$(echo "scale=3; $render / $base" | bc)
		printf '%-8s %-10s %5s %7s %5s %8.2f %8s  %s\n' "$name" "$res" "$ranks" "$threads" "$runs" \
			"$wall" "$render" "$ratio"
		printf '%s.rt\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$name" "$mode" "$res" "${spp:-1}" \
			"$ranks" "$threads" "$runs" "$wall" "$render" "$ratio" "$note" >>"$out"
	done
	# the per-tile cost on the wire, from the last 2x1 run's -v table
	awk -v s="$name" '/^1 /{printf "%-8s rank 1 of 2: %s tiles, %s bytes sent, %d bytes a tile, round trip %s us\n", s, $4, $8, $8 / ($4 ? $4 : 1), $9}' "$tmp/mpi2x1.log"
done
echo "load at the end $(cut -d' ' -f1-3 /proc/loadavg); rows in $out"
