#!/usr/bin/env bash
# The building benchmark (docs/results.md, "The building benchmark"): installs what is missing,
# builds (host release), then runs tools/eval/benchmark.py: missions in generated buildings,
# every one through the full algorithm and the keyframe baseline, and writes the distributions
# into docs/results.md. 56 minutes on 2 cores for the 40 missions (measured at 017aced); --ci runs the 5-mission
# subset CI runs (a few minutes).
#
#   scripts/benchmark.sh [--ci] [--missions N] [--work out/benchmark] [--results docs/results.md]
#
# Exit status: 0, or 1 when a mission failed to run or a view merged wrongly.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
work=out/benchmark; results=docs/results.md; extra=()
while [[ $# -gt 0 ]]; do
  case $1 in
    --ci) extra+=(--ci); work=out/benchmark-ci; results=""; shift ;;
    --missions) extra+=(--missions "$2"); shift 2 ;;
    --work) work=$2; shift 2 ;;
    --results) results=$2; shift 2 ;;
    *) echo "usage: $0 [--ci] [--missions N] [--work DIR] [--results FILE]" >&2; exit 2 ;;
  esac
done
scripts/bootstrap.sh
cmake --preset host-release >/dev/null
cmake --build --preset host-release
args=(--build build/host-release --work "$work" "${extra[@]}")
[[ -n $results ]] && args+=(--results "$results")
exec tools/eval/benchmark.py "${args[@]}"
