#!/bin/bash
# SPDX-License-Identifier: MIT
# msgraphs_relocalise_eval on a generated building where fitness alone took look-alike places
# (a room turned half round, one turned a quarter): with the map's negative evidence no
# relocalisation is wrong and most are right; with the test turned off (--max-seen-through 1)
# the same stops give wrong answers, so the evaluation can see the failure it guards against.
#   relocalise_eval_test.sh <msgraphs_sim> <msgraphs_relocalise_eval>
set -u
sim=$1; eval_tool=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
"$sim" --building 1002 --out "$work/run" --robots 1 --duration-s 90 --seed 12 --threads 1 \
  --benchmark > "$work/sim.log" 2>&1 || { cat "$work/sim.log"; echo "FAIL: simulator"; exit 1; }
"$eval_tool" --run "$work/run" --robot 1 --stops 6 --downtimes 2,4,6 > "$work/gated.log" 2>&1
rc=$?
cat "$work/gated.log"
[[ $rc == 0 ]] || { echo "FAIL: a relocalisation was wrong (exit $rc)"; exit 1; }
right=$(sed -n 's/^relocalise: \([0-9]*\) right.*/\1/p' "$work/gated.log")
[[ -n $right && $right -ge 8 ]] || { echo "FAIL: too few right relocalisations (${right:-none} of 18)"; exit 1; }
"$eval_tool" --run "$work/run" --robot 1 --stops 6 --downtimes 2,4,6 --max-seen-through 1 \
  > "$work/ungated.log" 2>&1
rc=$?
grep -E "WRONG|^relocalise:" "$work/ungated.log"
[[ $rc == 1 ]] || { echo "FAIL: without the negative evidence the evaluation saw no wrong answer (exit $rc)"; exit 1; }
echo "PASS: relocalisation never wrong"
