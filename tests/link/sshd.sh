#!/bin/sh
# rtsh over a real sshd on 127.0.0.1 (its own config, host key and user key
# in a temporary folder), the ssh client on the link simulator's pty at
# 30 KB/s and 100 ms: the picture comes, paced by the terminal's answers
# through sshd (every typed key echoes, the 95th percentile within 0.5 s,
# the target being 0.3 s; no backlog after the render: idle within the time
# one exact picture takes on the wire + 1.5 s, as in run.sh), and truecolor is found by asking (ssh forwards TERM,
# not COLORTERM). Skipped with a message where sshd cannot run.
# Usage: sshd.sh RTSH LINKSIM
set -u
rtsh=$1; sim=$2
case $rtsh in /*) ;; *) rtsh="$PWD/$rtsh" ;; esac
case $sim in /*) ;; *) sim="$PWD/$sim" ;; esac
results=${RTSH_TEST_RESULTS:-build/test-results}
mkdir -p "$results"
skip() { echo "SKIPPED: $*; rtsh over sshd not tested"; echo "0 0" >"$results/sshd.count"; exit 0; }
sshd=/usr/sbin/sshd
[ -x $sshd ] || skip "no $sshd (apt-get install -y openssh-server)"
command -v ssh >/dev/null 2>&1 && command -v ssh-keygen >/dev/null 2>&1 || skip "no ssh client"
if [ ! -d /run/sshd ]; then
	# sshd's privilege separation folder (made by the package's service).
	mkdir -p /run/sshd 2>/dev/null && chmod 755 /run/sshd || skip "no /run/sshd and cannot make it"
fi
d=$(mktemp -d)
trap 'kill $(cat "$d/sshd.pid" 2>/dev/null) 2>/dev/null; rm -rf "$d"' EXIT
ssh-keygen -q -t ed25519 -N '' -f "$d/host" || skip "ssh-keygen failed"
ssh-keygen -q -t ed25519 -N '' -f "$d/user" || skip "ssh-keygen failed"
cp "$d/user.pub" "$d/authorized_keys"
chmod 600 "$d/authorized_keys"
port=$((20000 + $$ % 20000))
cat >"$d/sshd_config" <<CONF
Port $port
ListenAddress 127.0.0.1
HostKey $d/host
AuthorizedKeysFile $d/authorized_keys
PidFile $d/sshd.pid
StrictModes no
PasswordAuthentication no
KbdInteractiveAuthentication no
UsePAM no
PermitRootLogin prohibit-password
PrintMotd no
PrintLastLog no
CONF
$sshd -f "$d/sshd_config" -E "$d/sshd.log" || skip "sshd did not start: $(tail -n 2 "$d/sshd.log")"
for i in $(seq 1 50); do [ -s "$d/sshd.pid" ] && break; sleep 0.1; done
sshcmd="ssh -F /dev/null -tt -p $port -i $d/user -o StrictHostKeyChecking=no -o UserKnownHostsFile=/dev/null -o LogLevel=ERROR 127.0.0.1"
env -i PATH="$PATH" HOME="$d" $sshcmd true </dev/null >/dev/null 2>&1 ||
	skip "ssh to 127.0.0.1:$port failed: $(tail -n 2 "$d/sshd.log")"
# 1024 samples, so that keys are typed while it renders (cornell's own 128
# can end within half a second of the first picture on a quiet machine)
line=$("$sim" --rate 30000 --rtt 0.1 --scenario refine --cols 200 --rows 60 --samples 1024 --timeout 90 -- \
	env -i PATH="$PATH" HOME="$d" TERM=xterm-256color $sshcmd \
	"cd '$PWD' && HOME='$d' '$rtsh' -t 2 -s 1024 scenes/cornell.rt")
echo "$line" >"$results/sshd.txt"
passed=0 failed=0
check() {
	if echo "$line" | tr ' ' '\n' | awk -F= '{ v[$1] = $2 } END { exit !('"$2"') }'; then
		passed=$((passed + 1)); echo "[       OK ] sshd: $1"
	else
		failed=$((failed + 1)); echo "[  FAILED  ] sshd: $1"; echo "    $line"
	fi
}
b=$(awk 'BEGIN { print 140000 / 30000 + 1.5 }')
check "30 KB/s over sshd: every key echoes" 'v["keys"] >= 1 && v["echoed"] == v["keys"]'
check "30 KB/s over sshd: echo p95 <= 0.5 s" 'v["echo_p95"] >= 0 && v["echo_p95"] <= 0.5'
check "30 KB/s over sshd: idle <= $b s after the render" "v[\"render_end\"] > 0 && v[\"idle_after_end\"] <= $b"
check "30 KB/s over sshd: truecolor from the terminal's answer" 'v["sgr24"] > 0'
echo "[==========] rtsh over sshd: $passed passed, $failed failed"
echo "$passed $failed" >"$results/sshd.count"
[ $failed = 0 ]
