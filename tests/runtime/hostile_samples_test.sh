#!/usr/bin/env bash
# A node maps a short simulated recording while hostile_peer sends it malformed, spoofed,
# oversized and undecodable samples on the fleet's topics and floods it: the node must refuse
# and count every class, keep mapping and exit cleanly.
#   hostile_samples_test.sh <msgraphs_node> <msgraphs_sim> <hostile_peer> <world> <domain>
set -u
node=$1; sim=$2; hostile=$3; world=$4; domain=$5
work=$(mktemp -d); trap '[[ -n "${KEEP:-}" ]] || rm -rf "$work"' EXIT; echo "work dir $work"
"$sim" --world "$world" --out "$work/run" --robots 1 --duration-s 60 --seed 3 > /dev/null || exit 1
cat > "$work/robot.conf" <<CONF
[robot]
id = 1
[lidar]
source = pcap
pcap = run/robot1/velodyne.pcap
[odometry]
source = candump
candump = run/robot1/odometry.log
[replay]
pace = lockstep
[link]
domain = $domain
loopback_only = true
[runtime]
status_period_s = 2
exit_after_done_s = 8
max_run_s = 120
CONF
"$node" --config "$work/robot.conf" > "$work/node.log" 2>&1 &
node_pid=$!
"$hostile" --domain "$domain" --target 1 --flood 2000 > "$work/hostile.log" 2>&1
hostile_rc=$?
wait $node_pid
node_rc=$?
cat "$work/hostile.log"; sed -n '/report:/,$p' "$work/node.log"
rc=0
check() {
  if grep -Eq "$1" "$work/node.log"; then echo "ok: $2"; else echo "MISSING: $2"; rc=1; fi
}
[[ $hostile_rc -eq 0 ]] || { echo "hostile_peer failed ($hostile_rc)"; rc=1; }
[[ $node_rc -eq 0 ]] || { echo "the node exited with $node_rc"; rc=1; }
check "report: [0-9]+ scans, [1-9][0-9]* keyframes" "the node kept mapping"
check "rejected [1-9][0-9]* unknown version" "unknown version refused"
check "[3-9][0-9]* bad sender" "sender 0, a spoofed own id and a mismatched sender refused"
check "[1-9][0-9]* oversize" "payload past the bound refused"
check "[1-9][0-9]* undecodable" "undeserialisable sample counted"
check "collab decoders refused 200[1-9] messages" "the flood's and the graph's corrupt payloads counted by the decoders"
[[ $rc -eq 0 ]] && echo "PASS: hostile samples refused and counted" || echo FAIL
exit $rc
