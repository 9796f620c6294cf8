#!/usr/bin/env bash
# The restart after a long mission (docs/performance.md, "Restart after a long mission"): one
# robot maps DURATION_S of the office world in lock-step with its checkpoint on, once with a
# generation every EVERY keyframes and once with the journal alone; each runs to the mission's
# end and is started again on the same folder. Printed per run:
# the keyframes mapped, the time from the restarted process's start to its first status line
# after the resume (mapping again), how the resume went, the checkpoint folder's size, and the
# first run's keyframe latency and peak RSS.
#
#   tools/eval/restart_eval.sh DURATION_S OUT_DIR [EVERY [MODES]]
#   EVERY: 50 (the default config); MODES: both (the default) or generations (no journal-only run).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
duration=${1:?duration in seconds}; out=${2:?output folder}; every=${3:-50}; modes=${4:-both}
[[ $modes == both || $modes == generations ]] || { echo "MODES: both or generations" >&2; exit 2; }
bin=${MSGRAPHS_BUILD_DIR:-build/host-release}
mkdir -p "$out"; out=$(realpath "$out")
run="$out/run"
if [[ ! -f "$run/mission.txt" ]]; then
  "$bin/tools/sim/msgraphs_sim" --world tools/sim/worlds/office.world --out "$run" --robots 1 \
    --duration-s "$duration" --seed 1 > "$out/sim.log"
fi
cat > "$out/robot.conf" <<CONF
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
domain = 77
loopback_only = true
[runtime]
status_period_s = 1
exit_after_done_s = 1
CONF
one() {  # one() NAME EVERY
  local name=$1 n=$2 dir="$out/$1"
  rm -rf "$dir"; mkdir -p "$dir"
  local conf=(--config "$out/robot.conf" --set checkpoint.dir="$dir/checkpoint"
              --set checkpoint.snapshot_every_keyframes="$n")
  # The mission to its end (its final solve and Finish record are journaled; the process then
  # leaves the folder as a kill would).
  "$bin/runtime/node/msgraphs_node" "${conf[@]}" > "$dir/first.log" 2>&1 || true
  local kf
  kf=$(grep -o "map [0-9]* keyframes" "$dir/first.log" | tail -1 | grep -o "[0-9]*")
  local size
  size=$(du -sm "$dir/checkpoint" | cut -f1)
  # The restart: from the process's start to its first status line after the resume.
  local t0 t1
  t0=$(date +%s.%N)
  "$bin/runtime/node/msgraphs_node" "${conf[@]}" --set runtime.max_run_s=60 > "$dir/restart.log" 2>&1 &
  pid=$!
  while kill -0 "$pid" 2>/dev/null && ! grep -q "resumed from checkpoint" "$dir/restart.log"; do
    sleep 0.05
  done
  t1=$(date +%s.%N)
  kill -9 "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
  echo "== $name (snapshot_every_keyframes = $n)"
  echo "  first run: $kf keyframes mapped; checkpoint folder $size MB: $(ls "$dir/checkpoint" | tr '\n' ' ')"
  grep -o "map [0-9]* keyframes (p50 [0-9]* ms, p99 [0-9]* ms)" "$dir/first.log" | tail -1 | sed 's/^/  first run /' || true
  grep -o "peak RSS [0-9.]* MB" "$dir/first.log" | tail -1 | sed 's/^/  first run /' || true
  grep -o "checkpoint: generation.*" "$dir/first.log" | tail -1 | sed 's/^/  /' || true
  grep "resumed from checkpoint" "$dir/restart.log" | sed 's/^/  /'
  grep "checkpoint: WARNING" "$dir/restart.log" | sed 's/^/  /' || true
  awk -v a="$t0" -v b="$t1" 'BEGIN { printf "  restart: process start to mapping again %.1f s\n", b - a }'
}
one generations "$every"
[[ $modes == generations ]] || one journal_only 0
