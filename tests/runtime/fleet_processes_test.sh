#!/usr/bin/env bash
# N msgraphs_node processes, one per simulated robot, on 127.0.0.1 with real Fast DDS: each maps
# its own recording (pcap + candump), they exchange distilled graphs, descriptors and
# room clouds, and every robot must place every other one (msgraphs_fleet_ate against the truth).
#
#   fleet_processes_test.sh <msgraphs_node> <msgraphs_sim> <msgraphs_fleet_ate> <world file> \
#                           <robots> <domain> [late | ros=<ros2_listener>]
#
# "ros=...": a ROS 2 subscriber (as RViz2 subscribes) must receive robot 1's walls, rooms,
# trajectory, map cloud and TF while the fleet runs. "late": the last robot
# starts only after the others have finished their recordings, so it must catch up from the
# transient-local history and the resync protocol.
set -u
node=$1; sim=$2; fleet_ate=$3; world=$4; robots=$5; domain=$6; late=${7:-}
ros_listener=""
[[ $late == ros=* ]] && { ros_listener=${late#ros=}; late=""; }
# Late: the first robots stay long enough for the last one to arrive.
quiet_s=6; [[ $late == late ]] && quiet_s=30
# Side by side at 4x the recorded pace (robots in the field progress together); the late test
# replays in lock-step, as fast as possible: the last robot arrives with its whole map.
pace=recorded; [[ $late == late ]] && pace=lockstep
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
"$sim" --world "$world" --out "$work/run" --robots "$robots" --duration-s 120 \
  --seed 1 --shared-rooms 2 > "$work/sim.log" || { cat "$work/sim.log"; exit 1; }
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
pace = $pace
speed = 4
[link]
domain = $domain
loopback_only = true
[runtime]
status_period_s = 10
exit_after_done_s = $quiet_s
max_run_s = 240
CONF
start() {
  local r=$1
  "$node" --config "$work/robot.conf" --set robot.id="$r" \
    --set lidar.pcap="run/robot$r/velodyne.pcap" --set odometry.candump="run/robot$r/odometry.log" \
    --set output.dir="out/robot$r" > "$work/robot$r.log" 2>&1 &
  pids[r]=$!
}
declare -a pids
first_batch=$robots
[[ $late == late ]] && first_batch=$((robots - 1))
for ((r = 1; r <= first_batch; r++)); do start "$r"; done
if [[ -n $ros_listener ]]; then
  "$ros_listener" --domain "$domain" --robot 1 --seconds 120 > "$work/ros.log" 2>&1 &
  ros_pid=$!
fi
if [[ $late == late ]]; then
  # Wait until the first robots' recordings have ended, then start the last one.
  for _ in $(seq 1 600); do
    done_count=$(grep -l "input done" "$work"/robot[0-9]*.log 2>/dev/null | wc -l)
    [[ $done_count -ge $first_batch ]] && break
    sleep 0.2
  done
  echo "robot $robots joins late (the others' recordings have ended)"
  start "$robots"
fi
rc=0
for ((r = 1; r <= robots; r++)); do
  if ! wait "${pids[r]}"; then echo "robot $r exited with an error"; rc=1; fi
done
for ((r = 1; r <= robots; r++)); do
  echo "--- robot $r"; sed -n '/report:/,$p' "$work/robot$r.log"
  grep -E "WARNING|error|failed" "$work/robot$r.log" | head -5
done
if [[ -n $ros_listener ]]; then
  wait $ros_pid || { echo "the ROS 2 subscriber did not get every topic"; rc=1; }
  cat "$work/ros.log"
fi
"$fleet_ate" --run "$work/run" --out "$work/out" --expect-merged --max-ate-m 0.15 || rc=1
[[ $rc -eq 0 ]] && echo "PASS: every robot merged every other robot" || echo "FAIL"
exit $rc
