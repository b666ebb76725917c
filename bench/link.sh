#!/bin/sh
# The "Over a slow link" figures of bench/README.md: the link simulator
# (build/tests/linksim) on cornell.rt in path mode at 200x60 cells,
# TERM=xterm-256color, 2 threads; the builds' runs interleaved, medians of
# RUNS runs (default 3).
#   BUILDS="RTSH-A RTSH-B ..." bench/link.sh
# Scenarios: 30 KB/s 100 ms refining at 128 and 1024 spp, Ctrl-C 2 s after
# the first picture, 1 MB/s 20 ms refining, and 100 MB/s 1 ms ("local": the
# render's end). Needs `make test-bins` (linksim). Takes a few minutes.
set -u
sim=${LINKSIM:-build/tests/linksim}
runs=${RUNS:-3}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
one() { # rtsh rate rtt scenario samples -> line
	"$sim" --rate "$2" --rtt "$3" --scenario "$4" --cols 200 --rows 60 --samples "$5" --timeout 240 -- \
		env -i PATH="$PATH" HOME="$tmp" TERM=xterm-256color "$1" -t 2 -s "$5" scenes/cornell.rt
}
med() { sort -n | awk '{ v[NR] = $1 } END { if (NR == 0) print "-"; else print v[int((NR + 1) / 2)] }'; }
scenarios="30000:0.1:refine:128 30000:0.1:refine:1024 30000:0.1:ctrlc:128 1000000:0.02:refine:128 100000000:0.001:refine:128"
for sc in $scenarios; do
	set -- $(echo "$sc" | tr ':' ' ')
	for r in $(seq 1 "$runs"); do
		i=0
		for b in $BUILDS; do
			i=$((i + 1))
			one "$b" "$1" "$2" "$3" "$4" >>"$tmp/$i.$sc"
		done
	done
done
i=0
for b in $BUILDS; do
	i=$((i + 1))
	echo "== $b"
	for sc in $scenarios; do
		f="$tmp/$i.$sc"
		printf '%-28s' "$sc"
		for k in echo_p50 echo_p95 echo_max render_end idle_after_end idle_after_ctrlc updates_per_s pictures_per_s bytes; do
			v=$(tr ' ' '\n' <"$f" | sed -n "s/^$k=//p" | med)
			[ "$v" = - ] || printf ' %s=%s' "$k" "$v"
		done
		echo
	done
done
