#!/usr/bin/env bash
# kill -9 of a node mid-mission, restart from its checkpoint: it resumes its map from its newest
# snapshot and the journal since (a generation every 10 keyframes here, so that a 30-keyframe
# run has several; nothing of the first part is lost), rejoins the fleet and the maps merge.
#   restart_test.sh <msgraphs_node> <msgraphs_sim> <msgraphs_fleet_ate> <world> <domain>
set -u
node=$1; sim=$2; fleet_ate=$3; world=$4; domain=$5
work=$(mktemp -d)
trap 'for p in $(jobs -p); do kill -9 $p 2>/dev/null; done; [[ -n "${KEEP:-}" ]] || rm -rf "$work"' EXIT
"$sim" --world "$world" --out "$work/run" --robots 2 --duration-s 120 --seed 1 --shared-rooms 2 \
  > /dev/null || exit 1
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
pace = recorded
speed = 2
[link]
domain = $domain
loopback_only = true
[checkpoint]
snapshot_every_keyframes = 10
[runtime]
status_period_s = 1
exit_after_done_s = 8
max_run_s = 200
CONF
start() {
  "$node" --config "$work/robot.conf" --set robot.id="$1" --set lidar.pcap="run/robot$1/velodyne.pcap" \
    --set odometry.candump="run/robot$1/odometry.log" --set output.dir="out/robot$1" \
    --set checkpoint.dir="checkpoint/robot$1" >> "$work/robot$1.log" 2>&1 &
}
start 1; pid1=$!
start 2; pid2=$!
# Kill robot 1 once it has mapped a quarter of its mission (30 keyframes of about 120).
for _ in $(seq 1 300); do
  kf=$(grep -o "map [0-9]* keyframes" "$work/robot1.log" | tail -1 | grep -o "[0-9]*")
  [[ -n "$kf" && $kf -ge 30 ]] && break
  sleep 0.1
done
kill -9 $pid1
wait $pid1 2>/dev/null
echo "robot 1 killed (SIGKILL) with $kf keyframes mapped; restarting it"
echo "===== restart" >> "$work/robot1.log"
start 1; pid1=$!
rc=0
wait $pid1 || { echo "robot 1 exited with an error"; rc=1; }
wait $pid2 || { echo "robot 2 exited with an error"; rc=1; }
grep "resumed from checkpoint" "$work/robot1.log" || { echo "robot 1 did not resume"; rc=1; }
grep -q "resumed from checkpoint .*: snapshot [1-9]" "$work/robot1.log" ||
  { echo "robot 1 did not resume from a snapshot"; rc=1; }
grep "checkpoint: WARNING" "$work/robot1.log" && { echo "robot 1 set checkpoint files aside"; rc=1; }
echo "checkpoint folder at the end: $(ls "$work/checkpoint/robot1" | tr '\n' ' ')"
for r in 1 2; do echo "--- robot $r"; sed -n '/report:/,$p' "$work/robot$r.log"; done
# Nothing lost: robot 1's final map starts where its mission started and holds more than it
# had when it was killed.
final=$(grep -c "^[0-9]" "$work/out/robot1/keyframes.tum")
first_kf=$(grep -m1 "^[0-9]" "$work/out/robot1/keyframes.tum" | cut -d' ' -f1)
first_truth=$(grep -m1 "^[0-9]" "$work/run/robot1/ground_truth.tum" | cut -d' ' -f1)
echo "robot 1: $kf keyframes when killed, $final at the end; first keyframe at $first_kf, mission start $first_truth"
awk -v a="$first_kf" -v b="$first_truth" 'BEGIN { exit !(a - b < 2.0 && b - a < 2.0) }' ||
  { echo "robot 1 lost the start of its map"; rc=1; }
[[ $final -gt $kf ]] || { echo "robot 1 did not continue mapping"; rc=1; }
"$fleet_ate" --run "$work/run" --out "$work/out" --expect-merged --max-ate-m 0.15 || rc=1
[[ $rc -eq 0 ]] && echo "PASS: robot 1 resumed after kill -9 and the maps merged" || echo FAIL
exit $rc
