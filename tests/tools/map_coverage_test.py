#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""tools/eval/map_coverage.py on synthetic maps: a wall of points as the reference; the same wall
shifted by 3 cm (covered in full); the wall with a 2 m gap cut out (a hole of several voxels,
counted and clustered); a map with a NaN and an infinite point (skipped, not fatal); a PCD with
16-bit fields (refused).

    map_coverage_test.py MAP_COVERAGE_PY
"""
import os
import re
import struct
import subprocess
import sys
import tempfile


def write_pcd(path, points, size=4):
    with open(path, "wb") as f:
        f.write(("# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE %d %d %d\nTYPE F F F\nCOUNT 1 1 1\n"
                 "WIDTH %d\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA binary\n"
                 % (size, size, size, len(points), len(points))).encode())
        for p in points:
            f.write(struct.pack("<3f", *p))


def wall(shift=0.0, gap=None):
    # A 10 m x 2 m wall in the x-z plane at y = 1, a point every 10 cm.
    out = []
    for i in range(101):
        for j in range(21):
            x, z = i * 0.1 + shift, j * 0.1
            if gap and gap[0] <= x <= gap[1]:
                continue
            out.append((x, 1.0, z))
    return out


def run(tool, ref, tested):
    r = subprocess.run([sys.executable, tool, ref, tested], capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def main():
    tool = sys.argv[1]
    failures = []
    with tempfile.TemporaryDirectory(prefix="msgraphs_map_coverage_") as work:
        ref, shifted, holed, odd, short = (os.path.join(work, n) for n in ("ref", "shift", "hole", "odd", "short"))
        write_pcd(ref, wall())
        write_pcd(shifted, wall(shift=0.03))
        write_pcd(holed, wall(gap=(3.0, 5.0)))
        write_pcd(odd, wall() + [(float("nan"), 0.0, 0.0), (float("inf"), 0.0, 0.0)])
        write_pcd(short, wall(), size=4)
        with open(short, "r+b") as f:  # claim 2-byte fields
            data = f.read().replace(b"SIZE 4 4 4", b"SIZE 2 2 2")
            f.seek(0)
            f.write(data)
        def holes(out):
            m = re.search(r"holes (\d+) voxels, (\d+) of them beside another", out)
            return (int(m.group(1)), int(m.group(2))) if m else None

        # The gap spans x 3.0-5.0 m: voxels 6..9 lack points; 7 and 8 have no covered neighbour
        # along x, over 5 voxels of height: 10 holes, all beside another.
        cases = [
            (shifted, lambda code, out: code == 0 and holes(out) == (0, 0) and "covered 100.00 %" in out,
             "a 3 cm shift is not covered in full"),
            (holed, lambda code, out: code == 0 and holes(out) == (10, 10), "the 2 m gap is not 10 clustered holes"),
            (odd, lambda code, out: code == 0 and holes(out) == (0, 0), "non-finite points were not skipped"),
            (short, lambda code, out: code != 0, "16-bit fields were not refused"),
        ]
        for tested, ok, failure in cases:
            code, out = run(tool, ref, tested)
            print(out.strip())
            if not ok(code, out):
                failures.append(failure)
    for f in failures:
        print("FAIL:", f)
    if failures:
        sys.exit(1)
    print("PASS: map coverage")


if __name__ == "__main__":
    main()
