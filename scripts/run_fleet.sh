#!/usr/bin/env bash
# A simulated fleet on this machine: N msgraphs_node processes (one per robot) over real Fast
# DDS on 127.0.0.1 map their recordings, merge their maps, and msgraphs_fleet_report gathers
# the result (report per robot, TUM trajectories, merged PCD map, SVG of the collaborative
# S-Graph, all in robot 1's frame).
#
#   scripts/run_fleet.sh [--world office] [--robots 3] [--duration-s 180] [--out out/fleet]
#                        [--inputs udp|lockstep] [--isolated]
#
# --isolated: every node on its own DDS domain: the same inputs and the same processes, but no
#   robot hears another (each collab thread idle). The node reports then give each robot's
#   timings without the fleet's matching beside them (docs/performance.md).
# --inputs udp (the demo): each node listens on UDP like a robot's payload computer (Velodyne
#   packets, CAN odometry as candump lines from a CAN-to-Ethernet gateway) and one
#   msgraphs_replay per robot sends its recording at the recorded pace; the run lasts as long
#   as the mission.
# --inputs lockstep: each node reads its pcap and candump files itself, as fast as it maps.
#
# The mission is simulated once (seed 1) into out/missions/<world>-<robots>-<duration>
# (MSGRAPHS_MISSIONS overrides) and kept for later runs. In --out: each node's own outputs in
# nodes/robotN/ (keyframes.tum, origins.csv, map.pcd, collab_graph.{csv,g2o}, report.txt),
# logs in logs/, and the fleet's gathered outputs at the top. MSGRAPHS_DOMAIN (42),
# MSGRAPHS_PORT_BASE (24000: robot N listens on base+10N .. base+10N+2) and MSGRAPHS_BUILD_DIR
# (build/host-release) let tests run it beside other fleets.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
world=office; robots=3; duration=180; out=out/fleet; inputs=lockstep; domain=${MSGRAPHS_DOMAIN:-42}
isolated=0
while [[ $# -gt 0 ]]; do
  case $1 in
    --world) world=$2; shift 2 ;;
    --robots) robots=$2; shift 2 ;;
    --duration-s) duration=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --inputs) inputs=$2; shift 2 ;;
    --isolated) isolated=1; shift ;;
    *) echo "usage: $0 [--world W] [--robots N] [--duration-s S] [--out DIR] [--inputs udp|lockstep] [--isolated]" >&2
       exit 2 ;;
  esac
done
[[ $inputs == udp || $inputs == lockstep ]] || { echo "--inputs udp or lockstep" >&2; exit 2; }
bin=${MSGRAPHS_BUILD_DIR:-build/host-release}
port_base=${MSGRAPHS_PORT_BASE:-24000}
missions=${MSGRAPHS_MISSIONS:-out/missions}
run="$missions/$world-$robots-$duration"
if [[ ! -f "$run/mission.txt" ]]; then
  echo "simulating the mission: $robots robots in $world for $duration s (seed 1) -> $run"
  mkdir -p "$missions"
  "$bin/tools/sim/msgraphs_sim" --world "tools/sim/worlds/$world.world" --out "$run" --robots "$robots" \
    --duration-s "$duration" --seed 1 > "$run.sim.log"
else
  echo "mission: $run (simulated earlier: $robots robots in $world for $duration s)"
fi
run=$(realpath "$run")
rm -rf "$out"; mkdir -p "$out/nodes" "$out/logs"
out=$(realpath "$out")
pids=(); replays=(); offsets=()
cleanup() { for p in "${pids[@]}" "${replays[@]}"; do kill -9 "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
for ((r = 1; r <= robots; r++)); do
  conf="$out/nodes/robot$r.conf"
  port=$(( port_base + 10 * r ))
  {
    echo "[robot]"; echo "id = $r"
    if [[ $inputs == udp ]]; then
      printf '[lidar]\nsource = udp\nbind = 127.0.0.1\ndata_port = %d\nposition_port = %d\n' $port $(( port + 1 ))
      printf '[odometry]\nsource = udp\nudp_port = %d\n' $(( port + 2 ))
    else
      printf '[lidar]\nsource = pcap\npcap = %s\n' "$run/robot$r/velodyne.pcap"
      printf '[odometry]\nsource = candump\ncandump = %s\n[replay]\npace = lockstep\n' "$run/robot$r/odometry.log"
    fi
    printf '[link]\ndomain = %d\nloopback_only = true\n' $(( isolated ? domain + r : domain ))
    printf '[runtime]\nstatus_period_s = 10\nmax_run_s = %d\n' $(( duration * 3 + 300 ))
    [[ $inputs == lockstep ]] && printf 'exit_after_done_s = 6\n'
    printf '[output]\ndir = %s\n' "$out/nodes/robot$r"
  } > "$conf"
  "$bin/runtime/node/msgraphs_node" --config "$conf" > "$out/logs/robot$r.log" 2>&1 &
  pids+=($!)
done
echo "$robots msgraphs_node processes started (Fast DDS domain $domain on 127.0.0.1; logs in $out/logs)"
# Progress: every node's status line as it prints it.
for ((r = 1; r <= robots; r++)); do
  tail -n +1 -F "$out/logs/robot$r.log" --pid "${pids[$((r - 1))]}" 2>/dev/null |
    awk '/^\[robot/ { print substr($0, 1, 150); fflush() }' &
done
if [[ $inputs == udp ]]; then
  sleep 2  # the nodes open their sockets and discover each other
  echo "msgraphs_replay: each robot's Velodyne packets and CAN odometry over UDP at the recorded pace ($duration s)"
  for ((r = 1; r <= robots; r++)); do
    port=$(( port_base + 10 * r ))
    "$bin/tools/msgraphs_replay" --pcap "$run/robot$r/velodyne.pcap" --candump "$run/robot$r/odometry.log" \
      --to 127.0.0.1 --data-port $port --position-port $(( port + 1 )) --can-port $(( port + 2 )) \
      > "$out/logs/replay$r.log" 2>&1 &
    replays+=($!)
  done
  rc=0
  for p in "${replays[@]}"; do wait "$p" || rc=1; done
  replays=()
  [[ $rc -eq 0 ]] || { echo "a replay failed:"; tail -n 5 "$out"/logs/replay*.log; exit 1; }
  sleep 5  # the last keyframes reach the other robots and are matched
  for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  for ((r = 1; r <= robots; r++)); do
    # The nodes stamp live inputs on arrival: how far the host clock ran ahead of the recording.
    offsets+=(--offset "$r=$(grep -o "recording time [0-9.]* is sent at host time [0-9.]*" "$out/logs/replay$r.log" |
      awk '{ printf "%.6f", $9 - $3 }')")
  done
fi
rc=0
for p in "${pids[@]}"; do wait "$p" || rc=1; done
pids=()
sleep 0.5
[[ $rc -eq 0 ]] || { echo "a node failed: see $out/logs"; }
echo
"$bin/tools/msgraphs_fleet_report" --out "$out/nodes" --dest "$out" --run "$run" --view 1 \
  ${offsets[@]+"${offsets[@]}"} || rc=1
exit $rc
