#!/bin/sh
# inroot.sh - run by tests/pkg/pkgtest.sh inside a fresh Debian 12 root, as
# root, with the two packages in /root/pkg: install, use, purge. Each step
# says "pkgtest: ..." when it passed; the first that does not ends the run
# with "pkgtest: FAIL: ..." and exit 1.
set -u
fail() { echo "pkgtest: FAIL: $*"; exit 1; }
ok() { echo "pkgtest: $*"; }
cd /root/pkg || fail "no /root/pkg"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq >/root/pkg/apt.log 2>&1 || fail "apt-get update: $(tail -n 3 /root/pkg/apt.log)"
apt-get install -y -qq --no-install-recommends ./roboelf_*.deb ./roboelf-sim_*.deb \
	>>/root/pkg/apt.log 2>&1 || fail "apt-get install: $(tail -n 5 /root/pkg/apt.log)"
ok "installed: $(dpkg-query -W -f '${Package} ${Version}\n' roboelf roboelf-sim | tr '\n' ' ')"

getent group roboelf >/dev/null || fail "no group roboelf"
for d in /var/lib/roboelf /var/log/roboelf; do
	[ "$(stat -c '%a %U:%G' "$d")" = "2770 root:roboelf" ] || fail "$d: $(stat -c '%a %U:%G' "$d")"
done
ok "the group roboelf; /var/lib/roboelf and /var/log/roboelf 2770 root:roboelf"
[ -x /etc/network/if-up.d/roboelf ] || fail "no executable ifupdown hook"
[ "$(grep -E '^  (file|path): ' /etc/roboelf/roboelf.yaml)" = "  file: /var/lib/roboelf/roboelf-calibration.txt
  path: /var/log/roboelf/roboelf.log" ] || fail "the conffile's paths"

# the unfilled template: refused by roboelf and --print, the hook does
# nothing and exits 0
cd /tmp || fail "no /tmp"
out=$(/usr/bin/roboelf --calibration file 2>&1 </dev/null)
rc=$?
[ $rc -eq 2 ] || fail "roboelf with the template: exit $rc: $out"
printf '%s\n' "$out" | head -n 1 | grep -q "^/etc/roboelf/roboelf.yaml: this site's configuration is not finished: [0-9]* values are still FILL-IN$" ||
	fail "roboelf with the template: $out"
out=$(/usr/bin/roboelf-tech --print controller.host 2>&1)
[ $? -eq 2 ] || fail "roboelf-tech --print with the template: $out"
for i in lo eth0; do
	out=$(IFACE=$i MODE=start ADDRFAM=inet sh /etc/network/if-up.d/roboelf 2>&1)
	rc=$?
	[ $rc -eq 0 ] && [ -z "$out" ] || fail "the hook on $i: exit $rc: $out"
done
ok "the template refused (roboelf, roboelf-tech --print: exit 2); the hook does nothing"

# two operators share the log: each roboelf appends to the one file (the
# controller is absent: exit 3 after the log is open)
useradd -m -G roboelf op1 && useradd -m -G roboelf op2 || fail "useradd"
sed -e 's|^  address: .*|  address: "127.0.0.1:9"|' \
	-e 's|^  file: .*|  file: /var/lib/roboelf/roboelf-calibration.txt|' \
	-e 's|^  path: .*|  path: /var/log/roboelf/roboelf.log|' \
	/usr/share/roboelf/config/roboelf.yaml >/tmp/dev.yaml || fail "dev.yaml"
chmod 644 /tmp/dev.yaml
for u in op1 op2; do
	out=$(cd /tmp && setpriv --reuid="$u" --regid="$u" --init-groups \
		/usr/bin/roboelf -c /tmp/dev.yaml --calibration file 2>&1 </dev/null)
	rc=$?
	[ $rc -eq 3 ] || fail "roboelf as $u: exit $rc: $out"
done
log=/var/log/roboelf/roboelf.log
[ "$(stat -c '%a %U:%G' "$log")" = "664 op1:roboelf" ] || fail "$log: $(stat -c '%a %U:%G' "$log")"
[ "$(grep -c ' INFO start: roboelf, config ' "$log")" = 2 ] || fail "$log: $(cat "$log")"
ok "two operators, one log: $log $(stat -c '%a %U:%G' "$log"), both starts in it"

# roboelf-sim: the installed demo, from a writable directory, runs the
# whole system on galil-sim and draws the fault's trace
mkdir /tmp/demo && cd /tmp/demo || fail "no /tmp/demo"
/usr/share/roboelf/demo.sh >/root/pkg/demo.log 2>&1 </dev/null || fail "the installed demo: exit $?: $(tail -c 600 /root/pkg/demo.log)"
ls /tmp/demo/roboelf-demo/roboelf-trace-*.csv >/dev/null 2>&1 || fail "the demo kept no trace"
[ "$(ls /tmp/demo/roboelf-demo/roboelf-trace-*.png | wc -l)" = 4 ] || fail "the demo drew no plots"
cd /tmp || fail "no /tmp"
ok "the installed demo ran (roboelf-sim): its trace and 4 plots in /tmp/demo/roboelf-demo"

# the installed roboelf against the installed galil-sim, by an operator,
# from a directory that is not the source tree, with the development
# configuration's robot and the site's places: Ready, the demo's fault, and
# the log, the trace and the calibration file where they belong
sed -e 's|^  file: .*|  file: /var/lib/roboelf/roboelf-calibration.txt|' \
	-e 's|^  path: .*|  path: /var/log/roboelf/roboelf.log|' \
	/usr/share/roboelf/config/roboelf.yaml >/tmp/var.yaml || fail "var.yaml"
chmod 644 /tmp/var.yaml
mkdir /tmp/demo2 && chown op2 /tmp/demo2 || fail "no /tmp/demo2"
(cd /tmp/demo2 && ROBOELF_DEMO_CONFIG=/tmp/var.yaml setpriv --reuid=op2 --regid=op2 --init-groups \
	/usr/share/roboelf/demo.sh) >/root/pkg/demo2.log 2>&1 </dev/null ||
	fail "the demo in the site's places: exit $?: $(tail -c 600 /root/pkg/demo2.log)"
cal=/var/lib/roboelf/roboelf-calibration.txt
[ -f "$cal" ] || fail "no calibration file $cal: $(ls -l /var/lib/roboelf)"
ls /var/log/roboelf/roboelf-trace-*.csv >/dev/null 2>&1 || fail "no trace in /var/log/roboelf: $(ls /var/log/roboelf)"
grep -q 'FAULT ENCODER: axis B' "$log" || fail "no FAULT ENCODER in $log"
grep -q 'RoboELF Ready for Use' /tmp/demo2/roboelf-demo/run-*/roboelf.out || fail "roboelf was never Ready"
ok "roboelf on galil-sim as op2: Ready, FAULT ENCODER on B; $cal, $(ls /var/log/roboelf/roboelf-trace-*.csv | head -n 1) and $log"

# an upgrade to the same sources rebuilt as a later version keeps the
# operator's edit of the conffile, the calibration file and the log
sed -i 's|^  address: FILL-IN|  address: 192.0.2.10|' /etc/roboelf/roboelf.yaml || fail "editing the conffile"
before=$(md5sum /etc/roboelf/roboelf.yaml "$cal" "$log")
apt-get install -y -qq --no-install-recommends /root/pkg/up/roboelf_*.deb /root/pkg/up/roboelf-sim_*.deb \
	>>/root/pkg/apt.log 2>&1 || fail "the upgrade: $(tail -n 5 /root/pkg/apt.log)"
cd /tmp || fail "no /tmp"
now=$(dpkg-query -W -f '${Version} ' roboelf roboelf-sim)
case $now in *+rebuilt1\ *+rebuilt1\ ) ;; *) fail "after the upgrade: versions $now" ;; esac
[ "$(md5sum /etc/roboelf/roboelf.yaml "$cal" "$log")" = "$before" ] ||
	fail "the upgrade changed: $(md5sum /etc/roboelf/roboelf.yaml "$cal" "$log")"
for d in /var/lib/roboelf /var/log/roboelf; do
	[ "$(stat -c '%a %U:%G' "$d")" = "2770 root:roboelf" ] || fail "after the upgrade, $d: $(stat -c '%a %U:%G' "$d")"
done
ok "upgraded to $now: the edited conffile, the calibration file and the log unchanged"
rm -f "$cal"* /var/log/roboelf/roboelf-trace-*

apt-get purge -y -qq roboelf-sim roboelf >>/root/pkg/apt.log 2>&1 || fail "apt-get purge: $(tail -n 5 /root/pkg/apt.log)"
[ ! -e /var/lib/roboelf ] || fail "the empty /var/lib/roboelf was kept"
[ -f "$log" ] || fail "the purge deleted the log"
[ ! -e /etc/roboelf/roboelf.yaml ] && [ ! -e /etc/network/if-up.d/roboelf ] || fail "the conffiles survived the purge"
ok "purged: the conffiles and the empty /var/lib/roboelf gone, the log kept"
ok "ok"
