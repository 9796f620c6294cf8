#!/usr/bin/env bash
# Clean shutdown on SIGTERM and SIGINT: the node stops its threads, prints its report and
# writes its output files, and exits 0. Also: a configuration error exits 2 with the file, line
# and key; a missing input exits 1 with the reason.
#   signal_shutdown_test.sh <msgraphs_node> <msgraphs_sim> <world> <domain>
set -u
node=$1; sim=$2; world=$3; domain=$4
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
"$sim" --world "$world" --out "$work/run" --robots 1 --duration-s 30 --seed 4 > /dev/null || exit 1
cat > "$work/robot.conf" <<CONF
[robot]
id = 5
[lidar]
source = pcap
pcap = run/robot1/velodyne.pcap
[odometry]
source = candump
candump = run/robot1/odometry.log
[replay]
pace = recorded
speed = 2
[link]
domain = $domain
loopback_only = true
[runtime]
status_period_s = 1
[output]
dir = out
CONF
rc=0
for sig in TERM INT; do
  rm -rf "$work/out"
  "$node" --config "$work/robot.conf" > "$work/$sig.log" 2>&1 &
  pid=$!
  sleep 4
  kill -s "$sig" $pid
  wait $pid; code=$?
  grep -q "SIG$sig received, shutting down" "$work/$sig.log" || { echo "no shutdown message for SIG$sig"; rc=1; }
  grep -q "robot 5 report:" "$work/$sig.log" || { echo "no report after SIG$sig"; rc=1; }
  [[ -s "$work/out/keyframes.tum" && -s "$work/out/report.txt" ]] || { echo "no output files after SIG$sig"; rc=1; }
  [[ $code -eq 0 ]] || { echo "exit code $code after SIG$sig"; rc=1; }
  echo "SIG$sig: exit $code, $(grep -c '^[0-9]' "$work/out/keyframes.tum" 2>/dev/null) keyframes written"
done
# Bad configuration: exit 2, naming the line.
printf '[robot]\nid = 1\n[mapping]\nbase_heigth_m = 0.5\n' > "$work/bad.conf"
"$node" --config "$work/bad.conf" > "$work/bad.log" 2>&1; code=$?
grep -q "bad.conf:4: mapping.base_heigth_m: unknown key" "$work/bad.log" && [[ $code -eq 2 ]] ||
  { echo "bad configuration: exit $code, $(cat "$work/bad.log")"; rc=1; }
# A live input that cannot be opened (no SocketCAN interface here): exit 1 with the reason.
printf '[robot]\nid = 1\n[lidar]\nsource = udp\ndata_port = 0\nposition_port = 0\n[odometry]\nsource = socketcan\ninterface = nosuchcan0\n[link]\ndomain = %s\nloopback_only = true\n' "$domain" > "$work/live.conf"
timeout 20 "$node" --config "$work/live.conf" > "$work/live.log" 2>&1; code=$?
grep -q "input failed: cannot open SocketCAN interface nosuchcan0" "$work/live.log" && [[ $code -eq 1 ]] ||
  { echo "missing CAN interface: exit $code, $(tail -3 "$work/live.log")"; rc=1; }
[[ $rc -eq 0 ]] && echo "PASS: clean shutdown on signals, clear errors" || echo FAIL
exit $rc
