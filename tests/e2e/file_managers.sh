#!/bin/sh
# README's file-manager snippets, taken from README.md as written (the
# blocks after <!-- snippet NAME -->), in the real programs under tmux:
# fzf's --preview, lf's previewer, ranger's scope.sh. Each shows a picture
# of a model and of a .rt scene in its preview pane: half blocks, in
# colour. A program that is not installed is skipped with a message
# (apt-get install -y fzf lf ranger).
set -u
s=rtsh-fm-$$
. tests/e2e/lib.sh
snippet() { awk -v name="$1" '$0 == "<!-- snippet " name " -->" { f = 1; next } f && /^```/ { if (c++) exit; next } f' README.md; }
# blocks: the half blocks on the screen
blocks() { screen | grep -o '▀\|▄\|█' | wc -l; }
# wait_picture WHAT: up to 10 s for at least 200 half blocks in colour
wait_picture() {
	for i in $(seq 1 100); do
		if [ "$(blocks)" -ge 200 ] && tmux capture-pane -t "$s" -p -e | grep -q "$(printf '\033')\[[34]8;[25];"; then
			return 0
		fi
		sleep 0.1
	done
	fail "$1: no picture in the preview pane; the screen:
$(screen | head -n 12)"
}
mkdir -p "$TMP/bin" "$TMP/home" "$TMP/files"
ln -s "$RTSH" "$TMP/bin/rtsh"
cp scenes/models/spot/spot_triangulated.obj "$TMP/files/cow.obj"
cp scenes/showcase.rt "$TMP/files/show.rt"
tmux new-session -d -s "$s" -x 120 -y 32 \
	"env -i PATH=\"$TMP/bin:$PATH\" HOME=\"$TMP/home\" XDG_CONFIG_HOME=\"$TMP/home/.config\" TERM=tmux-256color COLORTERM=truecolor sh" ||
	fail "tmux"
tmux send-keys -t "$s" "cd '$TMP/files'" Enter
tested=0

if command -v fzf >/dev/null 2>&1; then
	snippet fzf >"$TMP/fzf.sh"
	grep -q 'fzf --preview' "$TMP/fzf.sh" || fail "no fzf snippet in README.md"
	tmux send-keys -t "$s" "sh '$TMP/fzf.sh'" Enter
	wait_picture "fzf, the first file"
	tmux send-keys -t "$s" Up
	sleep 1
	wait_picture "fzf, the second file"
	tmux send-keys -t "$s" Escape
	sleep 0.5
	tested=$((tested + 1))
else
	echo "fzf is not installed: its snippet was not tried"
fi

if command -v lf >/dev/null 2>&1; then
	mkdir -p "$TMP/home/.config/lf"
	snippet lf >"$TMP/home/.config/lf/preview"
	chmod +x "$TMP/home/.config/lf/preview"
	grep -q 'rtsh --preview' "$TMP/home/.config/lf/preview" || fail "no lf snippet in README.md"
	# lf expands ~ from the password database, not $HOME: the full path.
	echo "set previewer $TMP/home/.config/lf/preview" >"$TMP/home/.config/lf/lfrc"
	tmux send-keys -t "$s" lf Enter
	sleep 1
	tmux send-keys -t "$s" j
	wait_picture "lf"
	tmux send-keys -t "$s" k
	sleep 1
	wait_picture "lf, the other file"
	tmux send-keys -t "$s" q
	sleep 0.5
	tested=$((tested + 1))
else
	echo "lf is not installed: its snippet was not tried"
fi

if command -v ranger >/dev/null 2>&1; then
	HOME="$TMP/home" XDG_CONFIG_HOME="$TMP/home/.config" ranger --copy-config=scope >/dev/null 2>&1 || fail "ranger --copy-config=scope"
	scope=$TMP/home/.config/ranger/scope.sh
	[ -f "$scope" ] || fail "no $scope"
	snippet ranger >"$TMP/ranger.txt"
	grep -q 'rtsh --preview' "$TMP/ranger.txt" || fail "no ranger snippet in README.md"
	# at the top of handle_extension's case, as README says
	awk -v snip="$TMP/ranger.txt" '{ print } /^handle_extension\(\)/ { h = 1 } h && /case "\$\{FILE_EXTENSION_LOWER\}" in/ { while ((getline l < snip) > 0) print l; h = 0 }' \
		"$scope" >"$scope.new" && mv "$scope.new" "$scope" && chmod +x "$scope"
	grep -q 'rtsh --preview' "$scope" || fail "the snippet did not go into scope.sh"
	# ranger turns previews off for root: on again for the test.
	tmux send-keys -t "$s" "ranger --cmd='set preview_files true' --cmd='set use_preview_script true'" Enter
	sleep 2
	tmux send-keys -t "$s" j
	wait_picture "ranger"
	tmux send-keys -t "$s" k
	sleep 1
	wait_picture "ranger, the other file"
	tmux send-keys -t "$s" q
	sleep 0.5
	tested=$((tested + 1))
else
	echo "ranger is not installed: its snippet was not tried"
fi
echo "file managers tried: $tested of 3"
tmux kill-session -t "$s"
