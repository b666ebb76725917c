#!/bin/sh
# Real terminals showing rtsh's real pixels (issue 12), under Xvfb:
#   - xterm -ti vt340 (sixel): `rtsh scenes/showcase.rt --pixels sixel`;
#   - kitty with Mesa's software GL (the kitty graphics protocol):
#     `rtsh scenes/showcase.rt --pixels kitty`.
# Text and background are black, so a screenshot (ImageMagick's import)
# trimmed of black is the picture alone: its size must be the terminal's
# pixel size (wider than the half-block picture could be: 2 pixels a cell
# across would give `cols`), and it must match the same view rendered with
# `rtsh -r WxH -o` within an RMS difference (sixel has 256 colours, kitty is
# exact). Each terminal is skipped with a message where it is missing.
# RTSH_PIXELS_SHOTS=DIR keeps the screenshots.
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
for tool in Xvfb import convert compare; do
	if ! command -v $tool >/dev/null 2>&1; then
		echo "SKIPPED: $tool is not installed (apt-get install -y xvfb imagemagick)"
		exit 0
	fi
done
display=:$((40 + $$ % 200))
Xvfb $display -screen 0 1000x800x24 -nolisten tcp >"$TMP/xvfb.log" 2>&1 &
xvfb=$!
trap 'kill $xvfb 2>/dev/null' EXIT
sleep 2
status=0
cols=100

# check NAME LIMIT COMMAND...: runs the terminal with rtsh in it, takes the
# screenshot, finds the picture, compares it with a batch render.
check() {
	name=$1 limit=$2; shift 2
	DISPLAY=$display "$@" >"$TMP/$name.log" 2>&1 &
	term=$!
	sleep 12
	DISPLAY=$display import -window root "$TMP/$name-shot.png" 2>>"$TMP/$name.log"
	kill $term 2>/dev/null
	wait $term 2>/dev/null
	[ -n "${RTSH_PIXELS_SHOTS:-}" ] && cp "$TMP/$name-shot.png" "$RTSH_PIXELS_SHOTS/"
	geo=$(convert "$TMP/$name-shot.png" -fuzz 1% -trim -format '%w %h %X %Y' info: 2>/dev/null)
	set -- $geo
	w=${1:-0} h=${2:-0} x=${3:-+0} y=${4:-+0}
	if [ "$w" -le $((2 * cols)) ]; then
		echo "$name: no picture wider than half blocks give ($cols cells): found ${w}x${h}"
		cat "$TMP/$name.log"
		status=1
		return
	fi
	"$RTSH" "$root/scenes/showcase.rt" -r ${w}x${h} -q -o "$TMP/ref.png" || { status=1; return; }
	convert "$TMP/$name-shot.png" -crop ${w}x${h}$x$y +repage "$TMP/crop.png"
	e=$(compare -metric RMSE "$TMP/crop.png" "$TMP/ref.png" null: 2>&1 | sed 's/.*(\(.*\)).*/\1/')
	if awk -v e="$e" -v l="$limit" 'BEGIN { exit !(e < l) }'; then
		echo "$name: the picture is ${w}x${h} pixels in $cols cells, RMS difference $e from the render (limit $limit)"
	else
		echo "$name: the ${w}x${h} picture differs from the render: RMS difference $e (limit $limit)"
		status=1
	fi
}

if command -v xterm >/dev/null 2>&1; then
	check xterm-sixel 0.04 xterm -ti vt340 -xrm 'XTerm*numColorRegisters: 256' \
		-xrm 'XTerm*maxGraphicSize: 2000x2000' -fg black -bg black -cr black -geometry ${cols}x60+0+0 \
		-e "$RTSH" "$root/scenes/showcase.rt" --pixels sixel
else
	echo "SKIPPED: xterm is not installed (apt-get install -y xterm)"
fi
if command -v kitty >/dev/null 2>&1; then
	check kitty 0.01 env LIBGL_ALWAYS_SOFTWARE=1 kitty --config NONE -o foreground=#000000 \
		-o background=#000000 -o cursor=#000000 -o initial_window_width=${cols}c \
		-o initial_window_height=50c -o remember_window_size=no \
		"$RTSH" "$root/scenes/showcase.rt" --pixels kitty
else
	echo "SKIPPED: kitty is not installed (apt-get install -y kitty libgl1-mesa-dri)"
fi
exit $status
