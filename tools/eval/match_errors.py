#!/usr/bin/env python3
"""Judges every keyframe's scan match against the ground truth: the error of the matched step
(previous keyframe to this one, base frames) against the true step, the truth interpolated at
both stamps (translation linearly, rotation by slerp). Prints, over all the pairs given, the
fitness of correct and of wrong matches (median / p90 / p99 / max), how many of each the
fitness gate refused, and every wrong match. The matches come from `msgraphs_slam --matches`;
run it with `--fitness-floor 1e9` to see every match the other tests accept, whatever its
fitness (that is how docs/s-graph.md's "Fitness gate" figures were taken).

    tools/eval/match_errors.py MATCHES.csv:GROUND_TRUTH.tum [...] [--wrong-m 0.15]

Exit 2 on a usage or reading error. Python 3 standard library only.
"""
import argparse
import bisect
import csv
import math
import sys


def quat_to_matrix(x, y, z, w):
    n = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def slerp(q0, q1, a):
    d = sum(p * q for p, q in zip(q0, q1))
    if d < 0:
        q1, d = [-q for q in q1], -d
    if d > 0.9995:
        return [p + a * (q - p) for p, q in zip(q0, q1)]
    th = math.acos(d)
    s0, s1 = math.sin((1 - a) * th) / math.sin(th), math.sin(a * th) / math.sin(th)
    return [s0 * p + s1 * q for p, q in zip(q0, q1)]


def pose(R, t):
    return [R[0] + [t[0]], R[1] + [t[1]], R[2] + [t[2]], [0.0, 0.0, 0.0, 1.0]]


def mul(A, B):
    return [[sum(A[i][k] * B[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def inv(T):
    R = [[T[j][i] for j in range(3)] for i in range(3)]
    t = [-sum(R[i][k] * T[k][3] for k in range(3)) for i in range(3)]
    return pose(R, t)


class Truth:
    def __init__(self, path):
        self.t, self.p = [], []
        with open(path) as f:
            for line in f:
                if not line.strip() or line.startswith("#"):
                    continue
                v = [float(x) for x in line.split()]
                self.t.append(v[0])
                self.p.append(v[1:8])
        if len(self.t) < 2:
            raise ValueError(f"{path}: fewer than two truth samples")
        if any(b <= a for a, b in zip(self.t, self.t[1:])):
            raise ValueError(f"{path}: truth stamps are not increasing")
        # The pairing rule of tools/include/msgraphs/tools/truth_pairing.hpp: bracketing samples
        # further apart than 2.5 of the truth's own median periods are a gap, not interpolated.
        periods = sorted(b - a for a, b in zip(self.t, self.t[1:]))
        self.gap_limit_s = 2.5 * periods[len(periods) // 2]

    def at(self, s):
        i = bisect.bisect_left(self.t, s)
        if i < len(self.t) and self.t[i] == s:
            p = self.p[i]
            return pose(quat_to_matrix(*p[3:]), p[:3])
        if i <= 0 or i >= len(self.t):
            return None
        t0, t1 = self.t[i - 1], self.t[i]
        if t1 - t0 > self.gap_limit_s:
            return None
        a = (s - t0) / (t1 - t0) if t1 > t0 else 0.0
        p0, p1 = self.p[i - 1], self.p[i]
        xyz = [p0[k] + a * (p1[k] - p0[k]) for k in range(3)]
        q = slerp(p0[3:], p1[3:], a)
        return pose(quat_to_matrix(*q), xyz)


def percentile(v, q):
    if not v:
        return float("nan")
    v = sorted(v)
    return v[min(len(v) - 1, int(q * len(v)))]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("pairs", nargs="+", help="MATCHES.csv:GROUND_TRUTH.tum")
    ap.add_argument("--wrong-m", type=float, default=0.15,
                    help="a match whose step is off by more than this is wrong (default 0.15 m)")
    args = ap.parse_args()
    correct, wrong, listed, unpaired, refused_fitness = [], [], [], 0, 0
    for pair in args.pairs:
        if ":" not in pair:
            print(f"match_errors: {pair}: expected MATCHES.csv:GROUND_TRUTH.tum", file=sys.stderr)
            return 2
        mpath, tpath = pair.rsplit(":", 1)
        try:
            truth = Truth(tpath)
            with open(mpath) as f:
                rows = list(csv.DictReader(f))
        except (OSError, ValueError) as e:
            print(f"match_errors: {e}", file=sys.stderr)
            return 2
        for r in rows:
            # Refused matches keep the odometry's step, not VGICP's: counted, not judged.
            refused_fitness += r["result"] == "fitness"
            if r["result"] != "accepted":
                continue
            a, b = truth.at(float(r["from_s"])), truth.at(float(r["to_s"]))
            if a is None or b is None:
                unpaired += 1
                continue
            M = pose(quat_to_matrix(float(r["qx"]), float(r["qy"]), float(r["qz"]), float(r["qw"])),
                     [float(r["x"]), float(r["y"]), float(r["z"])])
            E = mul(inv(mul(inv(a), b)), M)
            err_m = math.sqrt(sum(E[i][3] ** 2 for i in range(3)))
            fit, limit = float(r["fitness_m2"]), float(r["limit_m2"])
            if err_m > args.wrong_m:
                wrong.append(fit)
                listed.append((mpath, float(r["to_s"]), err_m, fit, limit))
            else:
                correct.append(fit)
    print(f"accepted matches judged: {len(correct) + len(wrong)} ({unpaired} outside the truth or in its gaps); "
          f"refused by fitness: {refused_fitness} (not judged: they keep the odometry's step)")
    for name, v in (("correct", correct), (f"wrong (> {args.wrong_m} m)", wrong)):
        print(f"  {name}: {len(v)}; fitness m^2 median {percentile(v, 0.5):.4f} p90 "
              f"{percentile(v, 0.9):.4f} p99 {percentile(v, 0.99):.4f} max "
              f"{max(v) if v else float('nan'):.4f}")
    for floor in (0.05, 0.07, 0.1):
        print(f"  a fixed limit of {floor} would refuse {sum(f > floor for f in correct)} correct and "
              f"{sum(f > floor for f in wrong)} wrong of these")
    for m, s, e, f, lim in sorted(listed, key=lambda x: -x[2]):
        print(f"  wrong: {m} at {s:.3f}: off by {e:.3f} m, fitness {f:.4f} (limit {lim:.4f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
