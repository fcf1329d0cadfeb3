#!/bin/bash
# netns_rig.sh - the network rig of tests/net: galil-sim runs in its own
# network namespace behind two veth pairs, roboelf on the host side.
#
#   data pair  (host rd<ID>h 10.231.<N>.1/30, namespace rd<ID>n .2): the
#              controller's command port; this is the "cable" that is pulled,
#              delayed and made lossy
#   mgmt pair  (host rm<ID>h 10.232.<N>.1/30, namespace rm<ID>n .2): the
#              control port that the test reads events from; never touched,
#              so the test sees the controller's events while the cable is out
#
# Usage (root or CAP_NET_ADMIN):
#   netns_rig.sh check                 exit 0, or 77 with "SKIP: <reason>"
#   netns_rig.sh setup ID              create namespace roboelf-net-ID
#   netns_rig.sh down ID | up ID       the host's end of the data pair down/up
#                                      (a pulled cable: no FIN, no RST)
#   netns_rig.sh loss ID PCT [DIR] [PROTO]
#                                      drop PCT % of the packets (iptables
#                                      statistic match) that DIR names: both
#                                      (the default, each way), ctl (the frames
#                                      the controller sends: its replies) or
#                                      pc (the frames the PC sends: requests);
#                                      each is dropped where it is received,
#                                      as a cable loses it (below). PROTO: tcp
#                                      (the command port: requests, replies,
#                                      the heartbeat), udp (the record stream,
#                                      DR) or all (the default); PROTO needs
#                                      DIR before it
#   netns_rig.sh delay ID MS BIN [PROTO]
#                                      hold every packet of PROTO (tcp, udp,
#                                      all: the default) that the controller
#                                      sends MS ms (BIN/nfq-delay, NFQUEUE 0)
#   netns_rig.sh rto ID MS [both]      rto_min MS on the data route, both ends;
#                                      the namespace's TCP (the controller's)
#                                      with linear retransmission timeouts
#   netns_rig.sh rto ID MS pc          rto_min MS on the host's (the PC's)
#                                      route only, as the package installs it;
#                                      the namespace (the controller) left at
#                                      the kernel's defaults: no rto_min on its
#                                      route (200 ms), tcp_thin_linear_timeouts
#                                      0. A real controller's TCP resends on a
#                                      timer nobody sets (docs/link.md)
#   netns_rig.sh clear ID              no loss, no delay, no rto_min
#   netns_rig.sh teardown ID           remove it all
#   netns_rig.sh addr ID               print "<data addr> <mgmt addr>" (.2)
#   netns_rig.sh exec ID CMD...        run CMD in the namespace
# A loss is a drop at the receiving end: the controller's frames in the
# host's INPUT chain (-i rd<ID>h, only this rig's interface), the PC's in
# the namespace's. A drop in the sender's own OUTPUT chain is not a lost
# frame: the sender's TCP is told the send failed, keeps the data unsent
# and sends it with its next segment, so its retransmission timer is never
# exercised (measured: no retransmission in the namespace at 5 % loss).
# Netem is not used: the development kernel has no sch_netem; iptables and
# NFQUEUE work both there and on a stock Debian 12 kernel.
# Exit codes: 0 done, 1 failure (message on stderr), 77 skip (check only).
set -u
SKIP=77
die() { echo "netns_rig: $*" >&2; exit 1; }
ids() {
	ID=$1
	case $ID in '' | *[!0-9]*) die "bad id '$ID'" ;; esac
	NS=roboelf-net-$ID
	N=$((ID % 250 + 1))
	DH=rd${ID}h; DN=rd${ID}n; MH=rm${ID}h; MN=rm${ID}n
	DHA=10.231.$N.1; DNA=10.231.$N.2; MHA=10.232.$N.1; MNA=10.232.$N.2
	PIDF=/run/roboelf-net-$ID.delay.pid
}
inns() { ip netns exec "$NS" "$@"; }

check() {
	command -v ip >/dev/null || { echo "SKIP: no 'ip' command (iproute2)"; exit $SKIP; }
	command -v iptables >/dev/null || { echo "SKIP: no 'iptables' (make deps installs it)"; exit $SKIP; }
	[ "$(id -u)" = 0 ] || { echo "SKIP: needs root (CAP_NET_ADMIN) to create network namespaces; run as root"; exit $SKIP; }
	t=roboelf-net-check-$$
	if ! ip netns add "$t" 2>/dev/null; then
		echo "SKIP: cannot create a network namespace (no CAP_NET_ADMIN?)"; exit $SKIP
	fi
	ok=1
	ip netns exec "$t" iptables -A INPUT -m statistic --mode random --probability 0.5 -j DROP 2>/dev/null || ok=0
	ip netns exec "$t" iptables -A OUTPUT -j NFQUEUE --queue-num 0 2>/dev/null || ok=0
	ip netns del "$t"
	[ $ok = 1 ] || { echo "SKIP: iptables statistic match or NFQUEUE target not available in this kernel"; exit $SKIP; }
	exit 0
}

# Namespaces of earlier runs that were killed before their teardown: the
# id is the test's pid (mod 100000); remove those whose process is gone.
sweep() {
	for old in $(ip netns list 2>/dev/null | sed -n 's/^roboelf-net-\([0-9][0-9]*\).*/\1/p'); do
		[ "$old" = "$ID" ] && continue
		kill -0 "$old" 2>/dev/null && continue
		(ids "$old"; teardown)
	done
}

setup() {
	sweep
	ip netns add "$NS" || die "cannot create namespace $NS"
	ip link add "$DH" type veth peer name "$DN" || die "cannot create veth $DH"
	ip link add "$MH" type veth peer name "$MN" || die "cannot create veth $MH"
	ip link set "$DN" netns "$NS" && ip link set "$MN" netns "$NS" || die "cannot move veth"
	ip addr add "$DHA/30" dev "$DH" && ip addr add "$MHA/30" dev "$MH" || die "addr"
	ip link set "$DH" up && ip link set "$MH" up || die "link up"
	inns ip link set lo up
	inns ip addr add "$DNA/30" dev "$DN" && inns ip addr add "$MNA/30" dev "$MN" || die "ns addr"
	inns ip link set "$DN" up && inns ip link set "$MN" up || die "ns link up"
}

kill_delay() {
	[ -f "$PIDF" ] || return 0
	pid=$(cat "$PIDF"); rm -f "$PIDF"
	# our own delayer only, by pid
	[ -n "$pid" ] && kill "$pid" 2>/dev/null
	for _ in $(seq 100); do kill -0 "$pid" 2>/dev/null || return 0; sleep 0.01; done
	kill -9 "$pid" 2>/dev/null; return 0
}

clear_rules() {
	kill_delay
	inns iptables -F INPUT 2>/dev/null
	inns iptables -F OUTPUT 2>/dev/null
	host_rules_del
	ip route del "$DNA/32" dev "$DH" 2>/dev/null
	inns ip route del "$DHA/32" dev "$DN" 2>/dev/null
	inns sysctl -qw net.ipv4.tcp_thin_linear_timeouts=0 2>/dev/null
	return 0
}

# PROTO as iptables words in $PM: none for all, "-p tcp" or "-p udp".
proto() {
	case $1 in
	all) PM= ;;
	tcp | udp) PM="-p $1" ;;
	*) die "bad protocol '$1' (tcp, udp, all)" ;;
	esac
}

# The namespace's INPUT receives the frames the PC sends, the host's INPUT
# (on rd<ID>h) those the controller sends.
loss() {
	pct=$1; dir=$2
	p=$(awk -v p="$pct" 'BEGIN { if (p + 0 <= 0 || p + 0 > 100) exit 1; printf "%.4f", p / 100 }') || die "bad loss '$pct'"
	case $dir in both | ctl | pc) ;; *) die "bad direction '$dir' (both, ctl, pc)" ;; esac
	proto "$3"
	if [ "$dir" != ctl ]; then
		# shellcheck disable=SC2086 # $PM: zero or two words
		inns iptables -A INPUT -i "$DN" $PM -m statistic --mode random --probability "$p" -j DROP || die "iptables"
	fi
	if [ "$dir" != pc ]; then
		# shellcheck disable=SC2086
		iptables -A INPUT -i "$DH" $PM -m statistic --mode random --probability "$p" -j DROP || die "host iptables"
	fi
	return 0
}

# The host's rules of this rig's interface only.
host_rules_del() {
	iptables -S INPUT 2>/dev/null | grep -e "-i $DH " | sed 's/^-A //' |
		while read -r rule; do
			# shellcheck disable=SC2086 # one argument per word
			iptables -D $rule 2>/dev/null
		done
	return 0
}

delay() {
	ms=$1; bin=$2
	proto "$3"
	[ -x "$bin/nfq-delay" ] || die "no '$bin/nfq-delay' (libnetfilter-queue-dev missing at build time?)"
	kill_delay
	fifo=$(mktemp -u /tmp/roboelf-nfq.XXXXXX); mkfifo "$fifo" || die "mkfifo"
	# not through a shell function: $! must be the pid that becomes
	# nfq-delay (ip netns exec exec's it)
	ip netns exec "$NS" "$bin/nfq-delay" 0 "$ms" >"$fifo" 2>&1 &
	echo $! >"$PIDF"
	# wait for its ready line (it ends at once on failure)
	line=$(timeout 5 head -1 "$fifo")
	if [ "${line#nfq-delay: ready}" = "$line" ]; then
		rm -f "$fifo"; kill_delay; die "nfq-delay did not start: $line"
	fi
	rm -f "$fifo"
	# shellcheck disable=SC2086
	inns iptables -A OUTPUT -o "$DN" $PM -j NFQUEUE --queue-num 0 || { kill_delay; die "iptables NFQUEUE"; }
}

rto() {
	ms=$1; ends=$2
	case $ends in both | pc) ;; *) die "bad ends '$ends' (both, pc)" ;; esac
	ip route replace "$DNA/32" dev "$DH" rto_min "${ms}ms" || die "host route"
	if [ "$ends" = pc ]; then
		# the controller's side as the kernel has it: whatever an
		# earlier 'rto ID MS' left there is removed
		inns ip route del "$DHA/32" dev "$DN" 2>/dev/null
		inns sysctl -qw net.ipv4.tcp_thin_linear_timeouts=0 || die "namespace sysctl"
		return 0
	fi
	inns ip route replace "$DHA/32" dev "$DN" rto_min "${ms}ms" || die "namespace route"
	inns sysctl -qw net.ipv4.tcp_thin_linear_timeouts=1 || die "namespace sysctl"
}

teardown() {
	kill_delay
	host_rules_del
	ip link del "$DH" 2>/dev/null
	ip link del "$MH" 2>/dev/null
	ip netns del "$NS" 2>/dev/null
	return 0
}

cmd=${1:-}; shift || true
case $cmd in
check) check ;;
setup) ids "$@"; setup ;;
down) ids "$@"; ip link set "$DH" down || die "link down" ;;
up) ids "$@"; ip link set "$DH" up || die "link up" ;;
loss) ids "$1"; loss "${2:?pct}" "${3:-both}" "${4:-all}" ;;
delay) ids "$1"; delay "${2:?ms}" "${3:?bin dir}" "${4:-all}" ;;
rto) ids "$1"; rto "${2:?ms}" "${3:-both}" ;;
clear) ids "$@"; clear_rules ;;
teardown) ids "$@"; teardown ;;
addr) ids "$@"; echo "$DNA $MNA" ;;
exec) ids "$1"; shift; exec ip netns exec "$NS" "$@" ;;
*) die "usage: netns_rig.sh check|setup|down|up|loss|delay|rto|clear|teardown|addr|exec ..." ;;
esac
