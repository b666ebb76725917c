#!/bin/sh
# The mouse in key mode, under tmux: SGR reports typed into the pane (as a
# terminal sends them with modes 1002 and 1006, which key mode turns on
# and gives back) orbit the model viewer's camera exactly as the arrow
# keys do (a Right arrow is a drag of two columns, an Up arrow a drag of
# one row up); the wheel brings the camera a tenth nearer to what it turns
# about; a click selects the object under the cursor; `0` brings back the
# first view; `turntable` spins the camera about the model's centre at
# its distance and height. Cameras are read from `save x.rt` and compared
# with what the rules of rtsh(1) give, computed here with awk.
set -u
s=rtsh-mouse-$$
fail() { echo "FAIL: $*"; tmux kill-session -t "$s" 2>/dev/null; exit 1; }
screen() { tmux capture-pane -t "$s" -p; }
wait_for() {
	for i in $(seq 1 100); do
		case $(screen) in *"$1"*) return 0 ;; esac
		sleep 0.1
	done
	fail "$2; the screen ends with:
$(screen | tail -n 6)"
}
keys() { tmux send-keys -t "$s" "$@"; sleep 0.3; }
mouse() { tmux send-keys -t "$s" -l "$(printf '\033[<%s' "$1")"; sleep 0.15; }
flag() { tmux display -p -t "$s" "#{$1}"; }
model=$PWD/scenes/models/spot/spot_triangulated.obj
[ -f "$model" ] || fail "no $model"

tmux new-session -d -s "$s" -x 100 -y 30 "env -i PATH=\"$PATH\" HOME=\"$TMP\" TERM=tmux-256color COLORTERM=truecolor sh" ||
	fail "tmux"
# save_view NAME KEYS...: a fresh model viewer, key mode, the keys (or
# "mouse REPORT" words), Esc, save NAME.rt.
session() {
	name=$1; shift
	tmux send-keys -t "$s" "cd '$PWD' && '$RTSH' '$model'" Enter
	wait_for "rtsh>" "no prompt"
	keys view Enter
	wait_for "Esc back" "no key mode"
	[ "$(flag mouse_sgr_flag)" = 1 ] || fail "key mode did not turn SGR mouse reports on"
	[ "$(flag mouse_button_flag)" = 1 ] || fail "key mode did not turn drag reports (1002) on"
	for k in "$@"; do
		case $k in
		m:*) mouse "${k#m:}" ;;
		*) keys "$k" ;;
		esac
	done
	sleep 0.3
	keys Escape
	wait_for "rtsh>" "Esc did not leave key mode"
	[ "$(flag mouse_sgr_flag)$(flag mouse_button_flag)" = 00 ] || fail "the mouse stayed on after key mode"
	keys "save $TMP/$name.rt" Enter
	wait_for "saved the scene to $TMP/$name.rt" "save $name.rt"
	keys quit Enter
	sleep 0.3
}
cam() { awk '$1 == "C" { gsub(",", " ", $2); gsub(",", " ", $3); print $2, $3, $4 }' "$TMP/$1.rt"; }
# the pivot: the model's box centre, the mesh line's position
pivot() { awk '$1 == "mesh" { gsub(",", " ", $3); print $3 }' "$TMP/$1.rt"; }
# same A B: the two cameras within 1e-9 (the same angles, summed in
# another order)
same() {
	echo "$(cam "$1") $(cam "$2")" | awk '{ for (i = 1; i <= 7; i++) { d = $i - $(i + 7); if (d < 0) d = -d; if (d > 1e-9) bad = 1 } exit bad }' ||
		fail "$1 and $2 differ: $(cam "$1") / $(cam "$2")"
}

session start
session keys Right Right Up
# two columns right twice (coalesced or not), then one row up; the
# releases carry the last position
session drag m:0\;40\;12M m:32\;41\;12M m:32\;42\;12M m:32\;43\;12M m:32\;44\;12M m:0\;44\;12m m:0\;40\;12M m:32\;40\;11M m:0\;40\;11m
same keys drag
echo "$(cam start) $(cam keys)" | awk '{ d = 0; for (i = 1; i <= 3; i++) d += ($i - $(i + 7)) ^ 2; exit !(d > 1e-6) }' ||
	fail "the arrows did not move the camera"
# The orbit keeps the distance to the pivot; yaw alone keeps the height.
session yaw Left Left Left
echo "$(cam start) $(cam yaw) $(pivot start)" | awk '{
	for (i = 1; i <= 3; i++) { a += ($i - $(i + 14)) ^ 2; b += ($(i + 7) - $(i + 14)) ^ 2 }
	exit !((sqrt(a) - sqrt(b)) ^ 2 < 1e-16 && ($2 - $9) ^ 2 < 1e-16) }' || fail "the orbit changed the distance or the height"
# The wheel: a tenth nearer the pivot, along the line to it.
session wheel m:64\;40\;12M
echo "$(cam start) $(cam wheel) $(pivot start)" | awk '{
	for (i = 1; i <= 3; i++) { want = $(i + 14) + 0.9 * ($i - $(i + 14)); d = $(i + 7) - want; if (d * d > 1e-16) bad = 1 }
	exit bad }' || fail "the wheel: $(cam wheel), expected 0.9 of the way from $(pivot start) to $(cam start)"
# 0: the first view again.
session home Right Up m:0\;40\;12M m:32\;30\;8M m:0\;30\;8m 0
same start home

# A click on the middle of the picture picks the model, one near its
# top-left corner (column 5, row 2: the help bar may take two rows, the
# picture then leaves a margin) the floor; with the camera turned up by 36 degrees, the
# same corner is sky: nothing.
tmux send-keys -t "$s" "'$RTSH' '$model'" Enter
wait_for "rtsh>" "no prompt"
keys view Enter
wait_for "Esc back" "no key mode"
mouse '0;50;14M'
mouse '0;50;14m'
wait_for "│ object 2 mesh │" "a click on the model did not select it"
mouse '0;5;2M'
mouse '0;5;2m'
wait_for "│ object 1 plane │" "a click on the floor did not select it"
keys i i i i i i i i i i i i
mouse '0;5;2M'
mouse '0;5;2m'
wait_for "nothing there" "a click on the sky"
wait_for "│ camera │" "the sky click did not select the camera"
# The keys still work with the mouse on.
keys Tab
wait_for "│ object 1 plane" "Tab after the mouse"
# Ctrl-C leaves key mode: the mouse goes off too.
keys C-c
wait_for "rtsh>" "Ctrl-C"
[ "$(flag mouse_sgr_flag)$(flag mouse_button_flag)" = 00 ] || fail "the mouse stayed on after Ctrl-C"
# The turntable: a turn in 2 s, stopped by a key after about one second.
keys "turntable 2" Enter
wait_for "turntable: a turn in 2 s" "no turntable"
sleep 1
keys x
wait_for "turntable stopped" "a key did not stop the turntable"
keys Escape
wait_for "rtsh>" "Esc after the turntable"
# the summary names the command that ran (it said "view:")
wait_for "turntable: 1 change kept" "no turntable summary after Esc"
keys "save $TMP/spin.rt" Enter
wait_for "saved the scene to $TMP/spin.rt" "save spin.rt"
echo "$(cam start) $(cam spin) $(pivot start)" | awk '{
	for (i = 1; i <= 3; i++) { a += ($i - $(i + 14)) ^ 2; b += ($(i + 7) - $(i + 14)) ^ 2; m += ($i - $(i + 7)) ^ 2 }
	exit !((sqrt(a) - sqrt(b)) ^ 2 < 1e-16 && ($2 - $9) ^ 2 < 1e-16 && m > 1e-4) }' ||
	fail "the turntable: $(cam spin) from $(cam start) about $(pivot start)"
keys quit Enter
sleep 0.3
case $(flag alternate_on) in 0) ;; *) fail "the alternate screen stayed on" ;; esac
tmux kill-session -t "$s"
