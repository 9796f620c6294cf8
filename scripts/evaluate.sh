#!/usr/bin/env bash
# The evaluation: installs what is missing, builds (host release), then runs every shipped world
# with 2 and 3 robots and writes docs/results.md (the paper's tables for our worlds, per-stage
# timing and peak memory, the nodes, the budget check), stamped with the commit. About 40
# minutes on 2 cores; the work folder (default out/eval) keeps every log and recording, and a
# second run reuses the recordings.
#
#   scripts/evaluate.sh [--work out/eval] [--results docs/results.md]
#
# Exit status: 0, or 1 when a run failed or a stage is over its budget (the results are
# written either way).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
work=out/eval; results=docs/results.md
while [[ $# -gt 0 ]]; do
  case $1 in
    --work) work=$2; shift 2 ;;
    --results) results=$2; shift 2 ;;
    *) echo "usage: $0 [--work DIR] [--results FILE]" >&2; exit 2 ;;
  esac
done
started=$(date +%s)
scripts/bootstrap.sh
cmake --preset host-release >/dev/null
cmake --build --preset host-release
build=build/host-release
mkdir -p "$work"
work=$(realpath "$work")
worlds=(office construction apartment rotated)
rc=0

echo; echo "=== 1/5 msgraphs_collab: every world, 2 robots in every ablation mode and the keyframe baseline, 3 robots"
tools/eval/multi_robot_runs.sh "$build" "$work" || rc=1

echo; echo "=== 2/5 msgraphs_slam: per-stage timing and memory, every robot of the 3-robot missions, one at a time"
mkdir -p "$work/slam"
for w in "${worlds[@]}"; do
  for k in 1 2 3; do
    "$build/tools/msgraphs_slam" --run "$work/sim3/$w" --robot $k > "$work/slam/$w-robot$k.txt" 2>&1 || rc=1
    grep -m1 "ATE RMSE" "$work/slam/$w-robot$k.txt" | sed "s/^/  $w robot $k: /"
  done
done

echo; echo "=== 3/5 scripts/run_fleet.sh: three msgraphs_node processes per world over real Fast DDS"
mkdir -p "$work/missions" "$work/fleet"
for w in "${worlds[@]}"; do
  # The same recordings as the collab runs (300 s, seed 1): no second simulation.
  ln -sfn "$work/sim3/$w" "$work/missions/$w-3-300"
  MSGRAPHS_MISSIONS="$work/missions" scripts/run_fleet.sh --world "$w" --robots 3 --duration-s 300 \
    --out "$work/fleet/$w" --inputs lockstep > "$work/fleet/$w.log" 2>&1 || rc=1
  grep "robot 1's view" "$work/fleet/$w.log" | sed "s/^/  $w: /" || true
done

echo; echo "=== 4/5 the long networked tests (ctest label eval): two nodes in network namespaces, unicast only, 20 % loss, a 30 s cut, a 20 kB/s radio"
ctest --test-dir "$build" -L eval --output-on-failure > "$work/eval-tests.log" 2>&1 || rc=1
grep -E "tests passed|Passed|Failed|Skipped" "$work/eval-tests.log" | sed "s/^/  /" || true

echo; echo "=== 5/5 the budget check (tools/eval/budgets.txt)"
budget_rc=0
# The worst of every stage over every robot of every world (section 2), the largest node of
# the office fleet (section 3).
slam_logs=()
for f in "$work"/slam/*.txt; do slam_logs+=(--slam-log "$f"); done
tools/eval/budget_check.py --build "$build" "${slam_logs[@]}" \
  --fleet "$work/fleet/office" --markdown "$work/budget.md" || budget_rc=$?
[[ $budget_rc -eq 0 ]] || rc=1

commit=$(git rev-parse --short HEAD)$(git diff --quiet HEAD -- . ':!docs/results.md' || echo "+uncommitted changes")
minutes=$(( ($(date +%s) - started) / 60 ))
# The building benchmark's section is kept as it is, to the end of the file: the table that
# tools/eval/benchmark.py --results writes between its markers and the hand-written analysis
# around it (only the marked block was kept before, and the analysis was lost).
bench_section=$(sed -n '/^## The building benchmark/,$p' "$results" 2>/dev/null || true)
tools/eval/results.py "$work" --commit "$commit" --budget-status $budget_rc --minutes $minutes > "$results.new"
[[ -z $bench_section ]] || printf '\n%s\n' "$bench_section" >> "$results.new"
mv "$results.new" "$results"
echo
echo "wrote $results (commit $commit, $minutes min); logs in $work"
sed -n '/## 1\./,/## 2\./p' "$results" | head -8
exit $rc
