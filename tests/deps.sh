#!/bin/sh
# Checks that the build's libraries are installed; on Debian, as root,
# installs what is missing, otherwise prints the exact command to run.
# Called by `make` before every build; quiet when all is present.
missing=""
have_header() {
	printf '#include <%s>\n' "$1" | ${CC:-cc} -E -x c - >/dev/null 2>&1
}
have_header png.h || missing="$missing libpng-dev"
have_header readline/readline.h || missing="$missing libreadline-dev"
have_header ncurses.h || missing="$missing libncurses-dev"
have_header assimp/cimport.h || missing="$missing libassimp-dev"
have_header cjson/cJSON.h || missing="$missing libcjson-dev"
have_header stb/stb_image.h || missing="$missing libstb-dev"
have_header X11/xpm.h || missing="$missing libxpm-dev"
have_header sixel/sixel.h || missing="$missing libsixel-dev"
have_header zlib.h || missing="$missing zlib1g-dev"
printf '#include <stdarg.h>\n#include <stddef.h>\n#include <setjmp.h>\n#include <cmocka.h>\n' |
	${CC:-cc} -E -x c - >/dev/null 2>&1 || missing="$missing libcmocka-dev"
command -v ${CC:-cc} >/dev/null 2>&1 || missing="$missing build-essential"
# Test-only packages: installed as root when missing, never required (the
# tests that need them say they were skipped).
if [ -z "$missing" ] && [ ! -x /usr/sbin/sshd ] && [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
	DEBIAN_FRONTEND=noninteractive apt-get install -y openssh-server >/dev/null 2>&1 || true
fi
# Optional: Open MPI for rtsh-mpi (`make mpi`); rtsh builds without it.
optional=""
command -v mpicc >/dev/null 2>&1 && command -v mpirun >/dev/null 2>&1 ||
	optional="openmpi-bin libopenmpi-dev"
if [ -n "$optional" ]; then
	if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1 &&
		DEBIAN_FRONTEND=noninteractive apt-get install -y $optional >/dev/null 2>&1; then
		echo "rtsh: installed $optional (for rtsh-mpi)" >&2
	else
		echo "rtsh: no Open MPI, so no rtsh-mpi; to build it: apt-get install $optional" >&2
	fi
fi
[ -z "$missing" ] && exit 0
cmd="apt-get install -y$missing"
if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
	echo "rtsh: installing$missing" >&2
	if DEBIAN_FRONTEND=noninteractive apt-get install -y $missing >/dev/null 2>&1 ||
		{ apt-get update >/dev/null 2>&1 && DEBIAN_FRONTEND=noninteractive apt-get install -y $missing >/dev/null; }; then
		exit 0
	fi
	echo "rtsh: could not install the packages; run: $cmd" >&2
	exit 1
fi
echo "rtsh: missing build dependencies; run: sudo $cmd" >&2
exit 1
