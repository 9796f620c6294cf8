#!/usr/bin/env python3
"""How much of a reference map another map covers: the holes a bounded cloud store leaves.

    map_coverage.py REFERENCE.pcd TESTED.pcd [--voxel-m 0.5]

Both maps are binary or ASCII PCD files with x y z float32 fields (msgraphs_node's map.pcd). The
reference is the same mission mapped with a store large enough to keep every keyframe's cloud.
A reference voxel is covered when the tested map has a point in it or in one of its 26
neighbours (the two runs' poses differ by centimetres, so a point may fall one voxel over): a
hole one voxel wide beside covered ones is not seen; the second figure counts the holes that
have uncovered neighbours too.
Prints the reference and tested voxel counts, the covered share and the holes: uncovered
voxels, and those that have uncovered neighbours too (a hole of more than one voxel)."""
import argparse
import math
import struct
import sys


def read_pcd(path):
    with open(path, "rb") as f:
        header = {}
        while True:
            line = f.readline()
            if not line:
                sys.exit(f"{path}: no DATA line")
            text = line.decode("ascii", "replace").strip()
            if text.startswith("#") or not text:
                continue
            key, _, value = text.partition(" ")
            header[key] = value
            if key == "DATA":
                break
        fields_named = header.get("FIELDS", "").split()
        if (fields_named[:3] != ["x", "y", "z"] or set(header.get("TYPE", "").split()) != {"F"}
                or set(header.get("SIZE", "").split()) != {"4"} or set(header.get("COUNT", "1").split()) != {"1"}):
            sys.exit(f"{path}: expected float32 fields of count 1, x y z first")
        n = int(header["POINTS"])
        fields = len(header["FIELDS"].split())
        if header["DATA"] == "binary":
            raw = f.read(4 * fields * n)
            if len(raw) != 4 * fields * n:
                sys.exit(f"{path}: {len(raw)} bytes of data, header says {4 * fields * n}")
            values = struct.unpack(f"<{fields * n}f", raw)
            return [values[i * fields:i * fields + 3] for i in range(n)]
        if header["DATA"] == "ascii":
            return [tuple(float(v) for v in line.split()[:3]) for line in f.read().decode().splitlines() if line.strip()]
        sys.exit(f"{path}: DATA {header['DATA']} not read")


def voxels(points, size):
    out = set()
    for x, y, z in points:
        if math.isfinite(x) and math.isfinite(y) and math.isfinite(z):
            out.add((int(x // size), int(y // size), int(z // size)))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("reference")
    ap.add_argument("tested")
    ap.add_argument("--voxel-m", type=float, default=0.5)
    a = ap.parse_args()
    ref = voxels(read_pcd(a.reference), a.voxel_m)
    test = voxels(read_pcd(a.tested), a.voxel_m)
    near = [(dx, dy, dz) for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1)]
    uncovered = {v for v in ref if not any((v[0] + d[0], v[1] + d[1], v[2] + d[2]) in test for d in near)}
    clustered = sum(1 for v in uncovered
                    if any((v[0] + d[0], v[1] + d[1], v[2] + d[2]) in uncovered for d in near if d != (0, 0, 0)))
    share = 100.0 * (len(ref) - len(uncovered)) / max(1, len(ref))
    print(f"reference {len(ref)} voxels of {a.voxel_m} m, tested {len(test)}; covered {share:.2f} %; "
          f"holes {len(uncovered)} voxels, {clustered} of them beside another")


if __name__ == "__main__":
    main()
