#!/usr/bin/env bash
# The README's main command: installs what is missing, builds (host release), checks what this
# machine grants a node, then runs the demo: a simulated three-robot mission in the office
# world (generated on first use, kept in out/missions/), three msgraphs_node processes over real
# Fast DDS on 127.0.0.1, each fed its robot's Velodyne packets and CAN odometry over UDP by
# msgraphs_replay at the recorded pace (3 minutes). It ends with a report per robot and writes
# everything into out/demo/ (docs/demo.md says what each file is).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
scripts/bootstrap.sh
cmake --preset host-release >/dev/null
cmake --build --preset host-release
node=build/host-release/runtime/node/msgraphs_node

echo
echo "=== 1. node self-check: platform capabilities and a Fast DDS exchange on loopback"
"$node" --self-check --domain 90
echo
echo "=== 2. three robots: three msgraphs_node processes fed over UDP, real Fast DDS on 127.0.0.1"
scripts/run_fleet.sh --world office --robots 3 --duration-s 180 --out out/demo --inputs udp
echo
echo "Output folder out/demo/: robotN.tum (every robot's keyframes in robot 1's frame, TUM for evo),"
echo "merged_map.pcd (PCL, CloudCompare), collab_graph.svg (the collaborative S-Graph from above),"
echo "report.txt; each node's own outputs (map.pcd, collab_graph.g2o, ...) in out/demo/nodes/robotN/."
