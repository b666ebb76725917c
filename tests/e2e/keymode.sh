#!/bin/sh
# Key mode under tmux at 160x48 with a truecolor terminal: `view` takes the
# whole screen (picture, status line, help bar); keys move the camera and a
# selected object, rotate one, undo one; Esc gives the shell's screen back;
# `save x.rt` holds every change, each at the place the documented step
# rule puts it (computed here from the scene file, independently of rtsh);
# `undo` in the shell takes back a key-mode edit; quit leaves the alternate
# screen.
set -u
s=rtsh-keymode-$$
fail() { echo "FAIL: $*"; tmux kill-session -t "$s" 2>/dev/null; exit 1; }
screen() { tmux capture-pane -t "$s" -p; }
# wait_for TEXT WHAT: up to 10 s for TEXT to be on the screen.
wait_for() {
	for i in $(seq 1 100); do
		case $(screen) in *"$1"*) return 0 ;; esac
		sleep 0.1
	done
	fail "$2; the screen ends with:
$(screen | tail -n 6)"
}
keys() { tmux send-keys -t "$s" "$@"; sleep 0.3; }

cat >"$TMP/k.rt" <<'EOF'
A 0.3 255,255,255
C 0,0,-10 0,0,1 70
L -10,10,-10 0.7 255,255,255
sp 0,0,0 4 230,60,50
sp 8,0,0 4 60,200,80
cu -6,0,0 0,1,0 3,3,3 70,110,235 0.9 0.5 50 0
pl 0,-2,0 0,1,0 200,200,200
EOF

# The step rule of rtsh(1), KEY MODE: L / 40, L the longest side of the box
# around the objects but planes, the lights and the camera. (This scene's
# cube is upright and untwisted: its box is centre +- scale/2.)
step=$(awk '
function add(x, y, z) {
	if (!n++) { lx = hx = x; ly = hy = y; lz = hz = z }
	if (x < lx) lx = x; if (x > hx) hx = x
	if (y < ly) ly = y; if (y > hy) hy = y
	if (z < lz) lz = z; if (z > hz) hz = z
}
$1 == "C" || $1 == "L" { split($2, p, ","); add(p[1], p[2], p[3]) }
$1 == "sp" { split($2, c, ","); r = $3 / 2; add(c[1] - r, c[2] - r, c[3] - r); add(c[1] + r, c[2] + r, c[3] + r) }
$1 == "cu" { split($2, c, ","); split($4, e, ",")
	add(c[1] - e[1] / 2, c[2] - e[2] / 2, c[3] - e[3] / 2); add(c[1] + e[1] / 2, c[2] + e[2] / 2, c[3] + e[3] / 2) }
END { L = hx - lx; if (hy - ly > L) L = hy - ly; if (hz - lz > L) L = hz - lz; printf "%.17g\n", L / 40 }
' "$TMP/k.rt")

# A plain shell in the pane, so that the pane outlives rtsh.
tmux new-session -d -s "$s" -x 160 -y 48 "env -i PATH=\"$PATH\" HOME=\"$TMP\" TERM=tmux-256color COLORTERM=truecolor sh" ||
	fail "tmux"
tmux send-keys -t "$s" "cd '$PWD' && '$RTSH' '$TMP/k.rt'" Enter
wait_for "1/1 spp" "no finished preview"
wait_for "rtsh>" "no prompt"

tmux send-keys -t "$s" view Enter
wait_for "Esc back" "no help bar in key mode"
wait_for " view │ k.rt │ camera │" "no key-mode status line"
[ "$(tmux display -p -t "$s" '#{alternate_on}')" = 1 ] || fail "key mode is not on the alternate screen"
case $(screen | tail -n 3) in *"rtsh>"*) fail "the prompt shows in key mode" ;; esac
esc=$(printf '\033')
# The picture in half blocks (since issue 27 a cell whose two pixels differ by less than their bytes'
# worth shows one colour, so a flat-shaded scene splits fewer cells: 658 of 7,360 here, against more
# than 1,000 before).
n=$(tmux capture-pane -t "$s" -p -e | grep -o '▀\|▄' | wc -l)
[ "$n" -gt 300 ] || fail "only $n half blocks in key mode"

# The camera flies two steps forward.
keys Up Up
# Object 1 (a sphere): two steps right, as one run of keys.
keys Tab
wait_for "│ object 1 sphere │" "Tab did not select object 1"
tmux capture-pane -t "$s" -p -e | grep -q "$esc\[38;2;255;205;0m\|$esc\[48;2;255;205;0m" ||
	fail "no selection outline (gold) on the picture"
keys Right Right
# Object 3 (the cube): ] turns its front to the right by 15 degrees.
keys Tab Tab
wait_for "│ object 3 cube │" "Tab Tab did not select object 3"
keys ]
# Object 2: a step left, then u takes it back.
keys BTab
wait_for "│ object 2 sphere │" "Shift+Tab did not select object 2"
keys Left u
# Path mode: the status line says so and samples come.
keys m
wait_for "│ path │" "m did not switch to path mode"
keys m
wait_for "│ whitted │" "m did not switch back"
tmux send-keys -t "$s" Escape
wait_for "view: 3 changes kept" "no summary after Esc"
wait_for "rtsh>" "no prompt after key mode"
case $(screen) in *"Esc back"*) fail "the help bar stayed after Esc" ;; esac
[ "$(tmux display -p -t "$s" '#{alternate_on}')" = 1 ] || fail "the shell's alternate screen was left"
screen | grep -q '^ k\.rt │ whitted │' || fail "no shell status line after key mode"
# The shell's picture comes back (its preview renders again).
for i in $(seq 1 50); do
	n=$(tmux capture-pane -t "$s" -p -e | grep -o '▀\|▄' | wc -l)
	[ "$n" -gt 300 ] && break
	sleep 0.1
done
[ "$n" -gt 300 ] || fail "only $n half blocks after key mode"

tmux send-keys -t "$s" "save $TMP/x.rt" Enter
wait_for "saved the scene to $TMP/x.rt" "save x.rt"
tmux send-keys -t "$s" undo Enter
sleep 0.3
tmux send-keys -t "$s" "save $TMP/y.rt" Enter
wait_for "saved the scene to $TMP/y.rt" "save y.rt"
tmux send-keys -t "$s" "help view" Enter
wait_for "back to the shell; every change stays" "help view does not list the keys"
# Output longer than the command area comes in the pager: q leaves it.
if tmux capture-pane -t "$s" -p | grep -q "Space next page"; then
	tmux send-keys -t "$s" q
	for i in $(seq 1 30); do
		sleep 0.1
		tmux capture-pane -t "$s" -p | grep -q "Space next page" || break
	done
fi
tmux send-keys -t "$s" quit Enter
for i in $(seq 1 50); do
	sleep 0.1
	[ "$(tmux display -p -t "$s" '#{alternate_on}')" = 0 ] && break
done
[ "$(tmux display -p -t "$s" '#{alternate_on}')" = 0 ] || fail "the alternate screen was not left"
tmux capture-pane -t "$s" -p | grep -q "rtsh.*k\.rt" || fail "the normal screen does not show the command line"
tmux kill-session -t "$s"

# field FILE KIND N FIELD COMPONENT: component (1-3) of field FIELD of the
# N-th line of kind KIND (C, sp, cu, ...).
field() {
	awk -v kind="$2" -v n="$3" -v f="$4" -v c="$5" '$1 == kind && ++k == n { split($f, v, ","); print v[c] }' "$1"
}
twist() {
	awk '$1 == "cu" { t = 0; for (i = 2; i <= NF; i++) if ($i ~ /^twist=/) t = substr($i, 7); print t }' "$1"
}
near() { # near GOT WANT WHAT
	awk -v g="$1" -v w="$2" 'BEGIN { d = g - w; exit !(g != "" && d * d < 1e-18) }' ||
		fail "$3 is ${1:-missing}, expected $2 (step $step)"
}
x=$TMP/x.rt y=$TMP/y.rt
[ -s "$x" ] || fail "no $x"
want=$(awk -v s="$step" 'BEGIN { printf "%.17g", -10 + 2 * s }')
near "$(field "$x" C 1 2 3)" "$want" "the camera's z after Up Up"
near "$(field "$x" C 1 2 1)" 0 "the camera's x"
want=$(awk -v s="$step" 'BEGIN { printf "%.17g", 2 * s }')
near "$(field "$x" sp 1 2 1)" "$want" "object 1's x after Right Right"
near "$(field "$x" sp 1 2 3)" 0 "object 1's z"
near "$(field "$x" sp 2 2 1)" 8 "object 2's x after Left and u"
t=$(twist "$x")
near "$(awk -v t="$t" 'BEGIN { print (t + 720) % 360 }')" 345 "the cube's twist after ]"
near "$(field "$x" cu 1 2 1)" -6 "the cube's x"
# undo in the shell took back the last key-mode edit still done (]).
near "$(twist "$y")" 0 "the cube's twist after undo"
near "$(field "$y" sp 1 2 1)" "$want" "object 1's x after undo"
echo "ok (step $step)"
