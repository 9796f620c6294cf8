#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The building benchmark: missions in generated buildings nobody tuned for.

Each mission is drawn from its index (deterministic): a building (msgraphs_sim --building SEED,
its style chosen so that every kind the benchmark must cover appears: rows of identical rooms,
mirrored wings, large halls, offices, schools, apartments, construction sites, angled wings),
2 to 5 robots starting at different times, visits that only look in from a doorway, walk part
of a room or explore it, people walking through some missions, and ground truth at 10 Hz to
1 kHz. Every mission is simulated, run through msgraphs_collab with the full algorithm and
with the keyframe-level baseline (the same recording), and summarised from their JSON
summaries (docs/collab-summary.md) and the simulator's shared-structure truth
(truth/shared.csv): which views could merge at all.

    tools/eval/benchmark.py --build build/host-release --work out/benchmark [--missions 40]
                            [--first 0] [--jobs 2] [--results docs/results.md] [--reuse-baseline]
    tools/eval/benchmark.py --build build/host-release --work out/bench-ci --ci   # 5 missions

Writes WORK/benchmark.json (every mission's figures), WORK/benchmark.md (the tables) and,
with --results FILE, replaces the section between the markers "<!-- benchmark begin -->" and
"<!-- benchmark end -->" of FILE with them. Exit status 0, or 1 when a mission failed to run
or a view merged wrongly.
"""
import argparse
import concurrent.futures
import json
import math
import os
import random
import statistics
import subprocess
import sys
import time

# The kinds every benchmark run covers, in this order, repeated: (style, symmetry) forced on
# the generator ("" lets the seed draw it).
KINDS = [
    ("hospital", "identical-row"),
    ("multi-wing", "mirrored-wings"),
    ("warehouse", ""),
    ("office", "identical-row"),
    ("apartment", ""),
    ("construction", ""),
    ("multi-wing", ""),
    ("office", ""),
]
TRUTH_RATES_HZ = [10, 50, 100, 1000]
# Shared walls that count as "visible structure" a pair could merge on: 2 m of wall face in the
# weakest direction of the pair's shared-wall scatter (about one short wall across the corridor).
SHARED_EIG_MIN_M = 2.0


def plan(index, ci):
    """The mission of this index: everything the simulator is told."""
    rng = random.Random(7919 * index + 17)
    style, symmetry = KINDS[index % len(KINDS)]
    # 2 to 5 robots, 2-3 most often; 120-180 s: 40 missions in about an hour on 2 cores.
    robots = 2 if ci else rng.choice([2, 2, 3, 3, 4, 5])
    duration = 120 if ci else rng.choice([120, 150, 180])
    mission = {
        "index": index,
        "building_seed": 1000 + index,
        "style": style,
        "symmetry": symmetry,
        "robots": robots,
        "duration_s": duration,
        "mission_seed": 1 + index,
        "shared_rooms": rng.choice([0, 1, 1, 2, 2, 3]),
        "people": rng.choice([0, 0, 0, 2, 4]),
        "truth_rate_hz": TRUTH_RATES_HZ[index % len(TRUTH_RATES_HZ)],
        "visit_kinds": rng.choice(["peek=0.3,partial=0.3,full=0.4", "peek=0.5,partial=0.3,full=0.2",
                                   "peek=0.1,partial=0.3,full=0.6"]),
        "start_delays": "random" if rng.random() < 0.6 else "none",
    }
    return mission


def sim_command(build, mission, out):
    cmd = [os.path.join(build, "tools/sim/msgraphs_sim"), "--building", str(mission["building_seed"]),
           "--out", out, "--robots", str(mission["robots"]), "--duration-s", str(mission["duration_s"]),
           "--seed", str(mission["mission_seed"]), "--shared-rooms", str(mission["shared_rooms"]),
           "--threads", "1"]
    if mission["style"]:
        cmd += ["--style", mission["style"]]
    if mission["symmetry"]:
        cmd += ["--symmetry", mission["symmetry"]]
    optional = {
        "--benchmark": None,  # the benchmark's motion: slips on (the options below override the rest)
        "--people": str(mission["people"]),
        "--truth-rate-hz": str(mission["truth_rate_hz"]),
        "--visit-kinds": mission["visit_kinds"],
        "--start-delays": mission["start_delays"],
    }
    return cmd, optional


def supported_options(build):
    """The simulator's options this build knows (older builds lack the mission kinds)."""
    out = subprocess.run([os.path.join(build, "tools/sim/msgraphs_sim")], capture_output=True, text=True)
    usage = out.stdout + out.stderr
    return {opt for opt in ["--benchmark", "--people", "--truth-rate-hz", "--visit-kinds", "--start-delays"] if opt in usage}


def run(cmd, log):
    with open(log, "w") as f:
        started = time.time()
        rc = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT).returncode
        return rc, time.time() - started


def run_mission(build, work, mission, options, reuse_baseline=False):
    """Simulates (unless already there) and runs both algorithms; returns the mission's record.
    With reuse_baseline, a keyframe baseline summary already in the folder is read, not rerun
    (the baseline does not use the merge rule: for measuring a change to the full algorithm)."""
    name = "m%03d-%s" % (mission["index"], mission["style"] or "any")
    folder = os.path.join(work, name)
    os.makedirs(folder, exist_ok=True)
    record = {"name": name, "mission": mission, "errors": []}
    recording = os.path.join(folder, "recording")
    done = os.path.join(recording, "robot%d" % mission["robots"], "velodyne.pcap")
    if not os.path.exists(done):
        cmd, optional = sim_command(build, mission, recording)
        for key, value in optional.items():
            if key in options:
                cmd += [key] if value is None else [key, value]
        rc, seconds = run(cmd, os.path.join(folder, "sim.log"))
        record["sim_s"] = seconds
        if rc != 0:
            record["errors"].append("simulation failed (sim.log)")
            return record
    collab = os.path.join(build, "tools/msgraphs_collab")
    for variant, extra in (("full", []), ("keyframes", ["--mode", "keyframes"])):
        summary = os.path.join(folder, variant + ".json")
        if variant == "keyframes" and reuse_baseline and os.path.exists(summary):
            with open(summary) as f:
                record[variant] = json.load(f)
            record[variant + "_s"] = 0.0
            continue
        cmd = [collab, "--run", recording, "--summary", summary, "--out", os.path.join(folder, variant)] + extra
        if variant == "full":
            cmd += ["--explain", os.path.join(folder, "explain")]
        rc, seconds = run(cmd, os.path.join(folder, variant + ".log"))
        record[variant + "_s"] = seconds
        if rc != 0 or not os.path.exists(summary):
            record["errors"].append("msgraphs_collab %s failed (%s.log)" % (variant, variant))
            continue
        with open(summary) as f:
            record[variant] = json.load(f)
    record["shared"] = read_shared(recording)
    record["building"] = read_key_values(os.path.join(recording, "building.txt"))
    return record


def read_key_values(path):
    out = {}
    if not os.path.exists(path):
        return out
    for line in open(path):
        parts = line.split()
        if len(parts) >= 2:
            out[parts[0]] = " ".join(parts[1:])
    return out


def read_shared(recording):
    """Per robot pair (a, b): what the simulator's truth says they shared (truth/shared.csv)."""
    path = os.path.join(recording, "truth", "shared.csv")
    pairs = {}
    if not os.path.exists(path):
        return pairs
    lines = [l.strip() for l in open(path) if l.strip() and not l.startswith("#")]
    if not lines:
        return pairs
    header = lines[0].split(",")
    for line in lines[1:]:
        row = dict(zip(header, line.split(",")))
        try:
            a, b = int(row.get("robot_a", 0)), int(row.get("robot_b", 0))
        except ValueError:
            continue
        pairs["%d-%d" % (min(a, b), max(a, b))] = row
    return pairs


def shares_structure(record, a, b):
    """True when the truth says robots a and b could place each other: both were inside one room,
    one looked into a room the other walked through, or both saw the same walls with at least
    SHARED_EIG_MIN_M of them in the weakest direction (shared.csv's eig_min_m: walls constraining
    one direction only, a corridor, cannot fix a transform). None when the truth is absent."""
    row = record.get("shared", {}).get("%d-%d" % (min(a, b), max(a, b)))
    if row is None:
        return None
    for key in ("rooms_both_inside", "peeked_by_a_entered_by_b", "peeked_by_b_entered_by_a"):
        if (row.get(key) or "").strip():
            return True
    try:
        return float(row.get("eig_min_m") or 0) >= SHARED_EIG_MIN_M
    except ValueError:
        return False


def percentile(values, q):
    if not values:
        return float("nan")
    values = sorted(values)
    k = (len(values) - 1) * q
    lo, hi = math.floor(k), math.ceil(k)
    return values[lo] + (values[hi] - values[lo]) * (k - lo)


def views_of(summary):
    return summary.get("views", []) if summary else []


def summarise(records):
    """Distributions over all missions, per algorithm."""
    out = {}
    for variant in ("full", "keyframes"):
        views = []
        ates, own_ates, bytes_total, first_merge = [], [], [], []
        causes = {}
        wrong = 0
        for r in records:
            s = r.get(variant)
            if not s:
                continue
            bytes_total.append(s.get("data", {}).get("total_bytes", 0))
            for robot in s.get("robots", []):
                own = robot.get("own_ate", {})
                if own.get("ok"):
                    own_ates.append(own.get("rmse_m"))
            for v in s.get("view_ate", []):
                if v.get("ok"):
                    ates.append(v.get("rmse_m"))
            for v in views_of(s):
                can = shares_structure(r, v["viewer"], v["robot"])
                views.append((r["name"], v, can))
                if v.get("verdict") == "wrong":
                    wrong += 1
                if v.get("merged") and v.get("first_merge_s") is not None:
                    first_merge.append(v["first_merge_s"])
                if not v.get("merged") or v.get("verdict") != "right":
                    cause = (v.get("explanation") or {}).get("cause") or v.get("verdict")
                    key = "%s (%s)" % (cause, "shared" if can else "not shared" if can is False else "unknown")
                    causes[key] = causes.get(key, 0) + 1
        shareable = [v for _, v, can in views if can]
        merged_shareable = [v for v in shareable if v.get("merged") and v.get("verdict") == "right"]
        out[variant] = {
            "missions": sum(1 for r in records if r.get(variant)),
            "views": len(views),
            "views_sharing": len(shareable),
            "views_sharing_merged_right": len(merged_shareable),
            "views_not_sharing_merged": sum(1 for _, v, can in views if can is False and v.get("merged")),
            "wrong": wrong,
            "aggregated_ate_m": {"median": percentile(ates, 0.5), "p90": percentile(ates, 0.9),
                                 "worst": max(ates) if ates else float("nan"), "n": len(ates)},
            "own_ate_m": {"median": percentile(own_ates, 0.5), "p90": percentile(own_ates, 0.9),
                          "worst": max(own_ates) if own_ates else float("nan"), "n": len(own_ates)},
            "bytes": {"median": percentile(bytes_total, 0.5), "p90": percentile(bytes_total, 0.9),
                      "worst": max(bytes_total) if bytes_total else float("nan"), "total": sum(bytes_total)},
            "first_merge_s": {"median": percentile(first_merge, 0.5), "p90": percentile(first_merge, 0.9)},
            "not_right_by_cause": dict(sorted(causes.items(), key=lambda kv: -kv[1])),
        }
    return out


def cm(x):
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else "%.1f" % (100 * x)


def markdown(records, summary, minutes, commit):
    lines = []
    f, k = summary["full"], summary["keyframes"]
    lines.append("Measured by `tools/eval/benchmark.py` at commit %s: %d missions in generated buildings, "
                 "%.0f min on this machine (2 cores)." % (commit, len(records), minutes))
    lines.append("")
    lines.append("| | full algorithm | keyframe baseline |")
    lines.append("|---|---|---|")
    def ratio(a, b):
        return "%d / %d (%.0f %%)" % (a, b, 100.0 * a / b) if b else "-"
    lines.append("| views that share a room or structure (truth): merged right | %s | %s |" % (
        ratio(f["views_sharing_merged_right"], f["views_sharing"]), ratio(k["views_sharing_merged_right"], k["views_sharing"])))
    lines.append("| views merged wrongly (all views) | **%d** of %d | %d of %d |" % (f["wrong"], f["views"], k["wrong"], k["views"]))
    lines.append("| views that share nothing yet merged | %d | %d |" % (f["views_not_sharing_merged"], k["views_not_sharing_merged"]))
    for key, label in (("aggregated_ate_m", "aggregated ATE per view, cm: median / p90 / worst"),
                       ("own_ate_m", "own-map ATE per robot, cm: median / p90 / worst")):
        lines.append("| %s | %s / %s / %s | %s / %s / %s |" % (label, cm(f[key]["median"]), cm(f[key]["p90"]), cm(f[key]["worst"]),
                                                            cm(k[key]["median"]), cm(k[key]["p90"]), cm(k[key]["worst"])))
    lines.append("| data per mission, MB: median / p90 / worst | %.3f / %.3f / %.3f | %.3f / %.3f / %.3f |" % (
        f["bytes"]["median"] / 1e6, f["bytes"]["p90"] / 1e6, f["bytes"]["worst"] / 1e6,
        k["bytes"]["median"] / 1e6, k["bytes"]["p90"] / 1e6, k["bytes"]["worst"] / 1e6))
    lines.append("| data, all missions: full / baseline | %.2f MB / %.2f MB (%.1f %%) | |" % (
        f["bytes"]["total"] / 1e6, k["bytes"]["total"] / 1e6, 100.0 * f["bytes"]["total"] / max(1, k["bytes"]["total"])))
    lines.append("| time to the first merge, s: median / p90 | %.0f / %.0f | %.0f / %.0f |" % (
        f["first_merge_s"]["median"], f["first_merge_s"]["p90"], k["first_merge_s"]["median"], k["first_merge_s"]["p90"]))
    lines.append("")
    lines.append("Views not merged right, by cause (the truth's own evidence under the rule, "
                 "`msgraphs_collab --explain`; shared: the truth says the two robots shared a room or "
                 "structure):")
    lines.append("")
    lines.append("| cause | full algorithm | keyframe baseline |")
    lines.append("|---|---|---|")
    for cause in sorted(set(f["not_right_by_cause"]) | set(k["not_right_by_cause"])):
        lines.append("| %s | %d | %d |" % (cause, f["not_right_by_cause"].get(cause, 0), k["not_right_by_cause"].get(cause, 0)))
    lines.append("")
    lines.append("Per mission (full algorithm; baseline bytes beside):")
    lines.append("")
    lines.append("| mission | building | robots, s | truth Hz | views merged right / sharing / all | wrong | first merge s | aggregated ATE cm (views) | MB full / baseline |")
    lines.append("|---|---|---|---|---|---|---|---|---|")
    for r in records:
        m = r["mission"]
        s, b = r.get("full"), r.get("keyframes")
        if not s:
            lines.append("| %s | %s | %d, %d | %d | failed: %s | | | | |" % (r["name"], m["style"], m["robots"], m["duration_s"],
                                                                       m["truth_rate_hz"], "; ".join(r["errors"])))
            continue
        views = views_of(s)
        sharing = [v for v in views if shares_structure(r, v["viewer"], v["robot"])]
        right = [v for v in views if v.get("merged") and v.get("verdict") == "right"]
        wrong = [v for v in views if v.get("verdict") == "wrong"]
        firsts = [v["first_merge_s"] for v in views if v.get("first_merge_s") is not None]
        ates = [v["rmse_m"] for v in s.get("view_ate", []) if v.get("ok")]
        building = r.get("building", {})
        label = "%s %s, %s rooms, %s deg" % (building.get("style", m["style"]), building.get("symmetry", ""),
                                              building.get("rooms", "?"), building.get("rotation_deg", "?"))
        lines.append("| %s | %s | %d, %d | %d | %d / %d / %d | %d | %s | %s | %.3f / %s |" % (
            r["name"], label, m["robots"], m["duration_s"], m["truth_rate_hz"], len(right), len(sharing), len(views),
            len(wrong), "%.0f" % min(firsts) if firsts else "-",
            " ".join(cm(a) for a in ates), s.get("data", {}).get("total_bytes", 0) / 1e6,
            "%.3f" % (b.get("data", {}).get("total_bytes", 0) / 1e6) if b else "-"))
    return "\n".join(lines) + "\n"


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--build", required=True)
    p.add_argument("--work", required=True)
    p.add_argument("--missions", type=int, default=40)
    p.add_argument("--first", type=int, default=0)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--ci", action="store_true", help="5 short 2-robot missions (CI)")
    p.add_argument("--results", help="a markdown file whose benchmark section is replaced")
    p.add_argument("--reuse-baseline", action="store_true",
                   help="read the keyframe baseline's summaries already in WORK instead of rerunning it")
    a = p.parse_args()
    if a.ci:
        a.missions = 5
    os.makedirs(a.work, exist_ok=True)
    started = time.time()
    options = supported_options(a.build)
    missions = [plan(i, a.ci) for i in range(a.first, a.first + a.missions)]
    records = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as pool:
        futures = {pool.submit(run_mission, a.build, a.work, m, options, a.reuse_baseline): m for m in missions}
        for future in concurrent.futures.as_completed(futures):
            r = future.result()
            records.append(r)
            print("done: %s%s" % (r["name"], " (" + "; ".join(r["errors"]) + ")" if r["errors"] else ""), flush=True)
    records.sort(key=lambda r: r["mission"]["index"])
    summary = summarise(records)
    minutes = (time.time() - started) / 60
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip() or "?"
    with open(os.path.join(a.work, "benchmark.json"), "w") as f:
        json.dump({"summary": summary, "missions": records, "minutes": minutes, "commit": commit,
                   "simulator_options": sorted(options)}, f, indent=1, default=str)
    text = markdown(records, summary, minutes, commit)
    with open(os.path.join(a.work, "benchmark.md"), "w") as f:
        f.write(text)
    if a.results:
        old = open(a.results).read() if os.path.exists(a.results) else ""
        begin, end = "<!-- benchmark begin -->", "<!-- benchmark end -->"
        block = begin + "\n" + text + end
        if begin in old and end in old:
            new = old[:old.index(begin)] + block + old[old.index(end) + len(end):]
        else:
            new = old + "\n## The building benchmark\n\n" + block + "\n"
        with open(a.results, "w") as f:
            f.write(new)
    print(text)
    failed = any(r["errors"] for r in records)
    return 1 if failed or summary["full"]["wrong"] > 0 else 0


if __name__ == "__main__":
    sys.exit(main())
