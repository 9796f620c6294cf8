#!/usr/bin/env bash
# Every msgraphs_collab run behind docs/multi-robot.md's tables, two at a time, deterministic:
# per world, 2-robot missions in each ablation mode, the keyframe baseline, feedback off, the
# cloud encodings (office and construction site), and a 3-robot mission with the full algorithm.
# Simulator recordings are made first where missing (300 s, seed 1).
#
#   tools/eval/multi_robot_runs.sh <build dir> <work dir>
#
# Each run's report goes to <work dir>/logs/<world>-<robots>-<variant>.txt.
set -euo pipefail
build=${1:?build dir}; work=${2:?work dir}
root=$(cd "$(dirname "$0")/../.." && pwd)
sim=$build/tools/sim/msgraphs_sim; collab=$build/tools/msgraphs_collab
mkdir -p "$work/logs"
worlds=(office construction apartment rotated)
for w in "${worlds[@]}"; do
  for n in 2 3; do
    [[ -f $work/sim$n/$w/robot$n/velodyne.pcap ]] && continue
    "$sim" --world "$root/tools/sim/worlds/$w.world" --out "$work/sim$n/$w" --robots "$n" \
      --duration-s 300 --seed 1 > "$work/logs/sim-$w-$n.txt"
  done
done
jobs_file=$work/jobs.txt; : > "$jobs_file"
for w in "${worlds[@]}"; do
  for mode in rooms rooms-fine rooms-walls rooms-walls-fine keyframes; do
    echo "$w 2 $mode --mode $mode" >> "$jobs_file"
  done
  echo "$w 2 feedback-off --feedback off" >> "$jobs_file"
  echo "$w 3 rooms-walls-fine --mode rooms-walls-fine" >> "$jobs_file"
done
for w in office construction; do
  echo "$w 2 cloud-f32 --cloud f32" >> "$jobs_file"
  echo "$w 2 cloud-q8 --cloud q8" >> "$jobs_file"
done
run_one() {
  local w=$1 n=$2 variant=$3; shift 3
  "$collab" --run "$work/sim$n/$w" "$@" > "$work/logs/$w-$n-$variant.txt" 2>&1
  echo "done: $w, $n robots, $variant"
}
export -f run_one; export collab work
xargs -P 2 -L 1 bash -c 'run_one "$@"' _ < "$jobs_file"
