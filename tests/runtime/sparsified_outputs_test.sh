#!/usr/bin/env bash
# A node whose keyframe store is small enough to sparsify during the mission: freed slots are
# taken by new keyframes, so slot order stops being time order. Its outputs must still be in time
# order: keyframes.tum strictly by stamp, the g2o export's keyframe vertices in the same order as
# keyframes.tum (the same poses) and its keyframe chain joining each vertex to the next one.
#   sparsified_outputs_test.sh <msgraphs_node> <msgraphs_sim> <world> <domain>
set -u
node=$1; sim=$2; world=$3; domain=$4
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
"$sim" --world "$world" --out "$work/run" --robots 1 --duration-s 60 --seed 6 > /dev/null || exit 1
cat > "$work/robot.conf" <<CONF
[robot]
id = 1
[lidar]
source = pcap
pcap = run/robot1/velodyne.pcap
[odometry]
source = candump
candump = run/robot1/odometry.log
[replay]
pace = lockstep
[mapping]
max_keyframes = 32
[link]
domain = $domain
loopback_only = true
[runtime]
exit_after_done_s = 1
[output]
dir = out
CONF
"$node" --config "$work/robot.conf" > "$work/node.log" 2>&1; code=$?
rc=0
[[ $code -eq 0 ]] || { echo "node exit $code"; tail -5 "$work/node.log"; rc=1; }
tum="$work/out/keyframes.tum"; g2o="$work/out/collab_graph.g2o"
[[ -s $tum && -s $g2o ]] || { echo "no keyframes.tum or collab_graph.g2o"; exit 1; }
sparsified=$(awk '$1 == "graph_sparsified" { print $2 }' "$work/out/stats.txt")
keyframes=$(grep -c '^[0-9]' "$tum")
echo "keyframes written: $keyframes; sparsified: ${sparsified:-?}"
# The test means something only if keyframes were sparsified (and their slots reused).
[[ ${sparsified:-0} -gt 0 ]] || { echo "nothing was sparsified"; rc=1; }
[[ $keyframes -le 32 ]] || { echo "more keyframes than the store holds"; rc=1; }
awk '/^[0-9]/ { if (seen && !($1 > last)) { print "keyframes.tum not in time order at line " NR; bad = 1 } last = $1; seen = 1 }
     END { exit bad }' "$tum" || rc=1
# Keyframe vertices (ids 1000 + slot, below the rooms' 1000000: docs/runtime.md) in file order against keyframes.tum.
awk '$1 == "VERTEX_SE3:QUAT" && $2 >= 1000 && $2 < 1000000 { print $2, $3, $4, $5 }' "$g2o" > "$work/vertices"
awk '/^[0-9]/ { print $2, $3, $4 }' "$tum" > "$work/tum_xyz"
paste -d' ' "$work/vertices" "$work/tum_xyz" | awk '
  { if (NF != 7) { print "g2o has " (NF < 7 ? "fewer" : "more") " keyframe vertices than keyframes.tum"; exit 1 }
    d = sqrt(($2 - $5)^2 + ($3 - $6)^2 + ($4 - $7)^2)
    if (d > 1e-4) { print "g2o vertex " NR " (" $1 ") is not keyframes.tum line " NR " (" d " m apart)"; exit 1 } }' || rc=1
[[ $(wc -l < "$work/vertices") -eq $keyframes ]] || { echo "g2o keyframe vertices: $(wc -l < "$work/vertices"), keyframes.tum: $keyframes"; rc=1; }
# The chain: each keyframe edge joins a vertex to the next one in that order.
awk 'NR == FNR { order[$1] = FNR; next }
     $1 == "EDGE_SE3:QUAT" && $2 >= 1000 && $2 < 1000000 && $3 >= 1000 && $3 < 1000000 {
       if (order[$3] != order[$2] + 1) { print "g2o chain edge " $2 " -> " $3 " skips or goes back"; bad = 1 } ++edges }
     END { if (edges + 1 != length(order)) { print "chain edges: " edges ", vertices: " length(order); bad = 1 } exit bad }' \
  "$work/vertices" "$g2o" || rc=1
[[ $rc -eq 0 ]] && echo "PASS: outputs in time order after sparsification" || echo FAIL
exit $rc
