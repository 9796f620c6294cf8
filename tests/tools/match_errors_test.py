#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""tools/eval/match_errors.py on a synthetic truth and matches file: a correct match, a wrong one,
one whose stamp falls in a gap of the truth (not judged, counted), one on a truth sample itself,
at 10 Hz and 1 kHz truth alike.

    match_errors_test.py MATCH_ERRORS_PY
"""
import os
import re
import subprocess
import sys
import tempfile

HEADER = "from_s,to_s,result,fitness_m2,limit_m2,x,y,z,qx,qy,qz,qw\n"


def truth_lines(rate_hz, gap):
    # The robot walks +x at 1 m/s for 10 s; `gap` removes the samples of 5.0-6.0 s.
    lines = []
    for i in range(int(10 * rate_hz) + 1):
        t = i / rate_hz
        if gap[0] < t < gap[1]:
            continue
        lines.append("%.6f %.6f 0 0 0 0 0 1\n" % (t, t))
    return lines


def run(tool, rate_hz):
    with tempfile.TemporaryDirectory(prefix="msgraphs_match_errors_") as work:
        truth = os.path.join(work, "truth.tum")
        with open(truth, "w") as f:
            f.writelines(truth_lines(rate_hz, (5.0, 6.0)))
        matches = os.path.join(work, "matches.csv")
        with open(matches, "w") as f:
            f.write(HEADER)
            f.write("1.03,2.03,accepted,0.02,0.05,1.0,0,0,0,0,0,1\n")   # right
            f.write("2.03,3.03,accepted,0.03,0.05,1.4,0,0,0,0,0,1\n")   # 0.4 m off
            f.write("4.97,5.55,accepted,0.02,0.05,0.58,0,0,0,0,0,1\n")  # ends in the gap
            f.write("7.0,8.0,accepted,0.02,0.05,1.0,0,0,0,0,0,1\n")     # on samples
            f.write("8.0,9.0,fitness,0.09,0.05,1.0,0,0,0,0,0,1\n")      # refused: counted only
        out = subprocess.run([sys.executable, tool, matches + ":" + truth], capture_output=True, text=True)
        return out.returncode, out.stdout + out.stderr


def main():
    tool = sys.argv[1]
    failures = []
    for rate in (10.0, 1000.0):
        rc, text = run(tool, rate)
        expect = [r"accepted matches judged: 3 \(1 outside the truth or in its gaps\); refused by fitness: 1",
                  r"correct: 2;", r"wrong \(> 0.15 m\): 1;", r"off by 0\.400 m"]
        if rc != 0:
            failures.append("%g Hz: exit %d" % (rate, rc))
        for e in expect:
            if not re.search(e, text):
                failures.append("%g Hz: no '%s' in:\n%s" % (rate, e, text))
    if failures:
        print("FAIL: " + "\n".join(failures))
        return 1
    print("PASS: matches judged against the interpolated truth, gaps not interpolated")
    return 0


if __name__ == "__main__":
    sys.exit(main())
