# Helpers for the command-file tests (sourced by each *.test).
# fail MESSAGE: print and exit 1.
fail() { echo "FAIL: $*" >&2; exit 1; }
# expect_status WANT COMMAND...: run, compare the exit status.
expect_status() {
	want=$1; shift
	"$@"; got=$?
	[ "$got" = "$want" ] || fail "exit status $got, expected $want: $*"
}
# pfm_row FILE ROW_FROM_TOP: the row's floats, one pixel (r g b) per line.
pfm_row() {
	file=$1 row=$2
	set -- $(head -c 64 "$file" | tr '\n' ' ')
	w=$2 h=$3
	hdr=$(printf 'PF\n%s %s\n%s\n' "$w" "$h" "$4" | wc -c)
	# PFM stores the bottom row first.
	off=$((hdr + (h - 1 - row) * w * 12))
	od -A n -t f4 -v -j "$off" -N $((w * 12)) "$file" | tr -s ' \n' '\n\n' | sed '/^$/d' | paste - - -
}
