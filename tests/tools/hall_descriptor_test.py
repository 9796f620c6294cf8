#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A 40 x 30 m hall gets a room descriptor (docs/merge-decision.md, issue: rooms of any size).

Two robots walk a hall of 40 x 30 m under a 5.5 m ceiling and the lobby beside it
(tests/tools/data/hall_40x30.world); msgraphs_collab runs the full algorithm. Passes when every
robot described both rooms (own rooms with a descriptor and a cloud: 2), refused no room cloud
as too large, thinned the hall's cloud to fit the session's bound instead, and the robots merged.

    hall_descriptor_test.py SIM COLLAB WORLD
"""
import json
import os
import subprocess
import sys
import tempfile


def main():
    sim, collab, world = sys.argv[1:4]
    with tempfile.TemporaryDirectory(prefix="msgraphs_hall_") as work:
        run = os.path.join(work, "run")
        subprocess.run([sim, "--world", world, "--out", run, "--robots", "2", "--duration-s", "120",
                        "--seed", "3", "--threads", "1"], check=True, stdout=subprocess.DEVNULL)
        summary = os.path.join(work, "summary.json")
        subprocess.run([collab, "--run", run, "--summary", summary], check=True, stdout=subprocess.DEVNULL)
        with open(summary) as f:
            s = json.load(f)
    failures = []
    for robot in s["robots"]:
        st = robot["session"]
        print("robot %d: %d own rooms described, peak room cloud %d points, %d clouds too large, %d refused" % (
            robot["robot"], st["own_rooms"], st["room_points_peak"], st["room_clouds_too_large"], st["rooms_refused"]))
        if st["own_rooms"] < 2:
            failures.append("robot %d described %d rooms, not the hall and the lobby" % (robot["robot"], st["own_rooms"]))
        if st["room_clouds_too_large"] != 0 or st["rooms_refused"] != 0:
            failures.append("robot %d refused a room" % robot["robot"])
    merged = [v for v in s["views"] if v["merged"]]
    wrong = [v for v in s["views"] if v["verdict"] == "wrong"]
    print("views merged %d of %d, wrong %d" % (len(merged), len(s["views"]), len(wrong)))
    if wrong:
        failures.append("a view merged wrongly")
    if failures:
        print("FAIL: " + "; ".join(failures))
        return 1
    print("PASS: the hall gets a descriptor")
    return 0


if __name__ == "__main__":
    sys.exit(main())
