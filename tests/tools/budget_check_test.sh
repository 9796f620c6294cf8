#!/usr/bin/env bash
# tools/eval/budget_check.py against a budget the CAN odometry decoder cannot meet (1 ps a
# sample) and one it always meets (1 s): it must exit 1 naming the stage, then 0.
#   budget_check_test.sh <source dir> <build dir>
set -u
src=$1; build=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
row() { echo "can_odometry_sample bench:drivers:BM_CanFramesToPose per_item $1 $1 us"; }
row 0.000001 > "$work/over.txt"
row 1000000 > "$work/within.txt"
rc=0
"$src/tools/eval/budget_check.py" --build "$build" --budgets "$work/over.txt" > "$work/over.log" 2>&1
code=$?
cat "$work/over.log"
[[ $code -eq 1 ]] || { echo "over budget: exit $code, expected 1"; rc=1; }
grep -q "can_odometry_sample .*OVER BUDGET" "$work/over.log" || { echo "the stage over budget is not named"; rc=1; }
"$src/tools/eval/budget_check.py" --build "$build" --budgets "$work/within.txt" > "$work/within.log" 2>&1
code=$?
cat "$work/within.log"
[[ $code -eq 0 ]] || { echo "within budget: exit $code, expected 0"; rc=1; }
"$src/tools/eval/budget_check.py" --build "$work/no-such-build" --budgets "$work/within.txt" > /dev/null 2>&1
code=$?
[[ $code -eq 2 ]] || { echo "no benchmark binary: exit $code, expected 2"; rc=1; }
[[ $rc -eq 0 ]] && echo "PASS: budget check" || echo FAIL
exit $rc
