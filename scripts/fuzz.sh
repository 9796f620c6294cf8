#!/bin/bash
# Builds the libFuzzer targets (preset `fuzz`: Debian clang, ASan + UBSan) and runs each for
# SECONDS (default 60). Seeds come from the public data set when it is there (copied to a
# temporary corpus, never into the repository). Exits non-zero on the first finding; the
# crashing input is kept in build/fuzz/artifacts/.
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]      # CI runs: scripts/fuzz.sh 10
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_EACH=${1:-60}
shift || true
TARGETS=("$@")
[ ${#TARGETS[@]} -eq 0 ] && TARGETS=(velodyne_decoder pcap_reader candump_parser can_decoder collab_messages collab_session node_config pcd_reader checkpoint_files)
DATA=${MSGRAPHS_DATA_DIR:-$(pwd)/../shared/data}

cmake --preset fuzz >/dev/null
# Only the fuzz targets (and what they link): the rest of the tree is not fuzzed here.
cmake --build --preset fuzz --target "${TARGETS[@]/#/fuzz_}" >/dev/null

WORK=$(mktemp -d); trap 'rm -rf "$WORK"' EXIT
mkdir -p build/fuzz/artifacts
mkdir -p "$WORK"/{velodyne_decoder,pcap_reader,candump_parser,can_decoder,collab_messages,collab_session,node_config,pcd_reader,checkpoint_files}
# The shipped example configuration seeds the config fuzzer.
cp runtime/node/example.conf "$WORK/node_config/"
# PCD seeds: a small binary map as the node writes it, an ascii file with an extra field.
printf '# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA binary\n' \
  > "$WORK/pcd_reader/binary.pcd"
head -c 24 /dev/zero >> "$WORK/pcd_reader/binary.pcd"
printf 'VERSION .7\nFIELDS x y z intensity\nSIZE 4 4 4 2\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 3 7\nnan 0 0 1\n' \
  > "$WORK/pcd_reader/ascii.pcd"
if [ -d "$DATA/pcap" ]; then
  # Single packets of the einride recording, and the small captures whole.
  python3 - "$DATA/pcap/einride_vlp16_recording_1000pkts.bin" "$WORK/velodyne_decoder" <<'PY'
import sys
raw = open(sys.argv[1], 'rb').read()
for i in range(0, 40):
    open(f"{sys.argv[2]}/packet{i}", 'wb').write(raw[i * 1206 * 25:(i * 25 + 1) * 1206])
PY
  for f in lidarutils_velodyne_example_vlp16.pcap lidarutils_velodyne_vlp16_pid0x21.pcap \
           lidarutils_velodyne_vlp32_actually_hdl32e.pcap; do
    cp "$DATA/pcap/$f" "$WORK/pcap_reader/"
  done
fi
[ -f "$DATA/can/cantools_readme_candump_abs.log" ] && cp "$DATA/can/cantools_readme_candump_abs.log" "$WORK/candump_parser/"
printf '(1700000000.123456) can0 120#1A2B3C4D5E6F7788\n(1700000000.123456789) vcan0 12345678#R\n(1.000000) can1 14C##5AABB\n' \
  > "$WORK/candump_parser/handmade.log"

# Seeds for the collaboration messages and the session: one valid message of each kind (kind
# byte as CollabMessageType, body; the targets append the CRC).
python3 - "$WORK/collab_messages" <<'PY'
import struct, sys
d = sys.argv[1]
wall = struct.pack('<II3ffffffffffff', 7, 2, 1.0, 0.0, 0.0, -2.0, 1e-4, 0, 0, 1e-4, 0, 1e-4, 2.0, -1.0, 2.0, 1.0)
room = struct.pack('<IIBfffffiiii', 3, 2, 0, 1.0, 2.0, 0.1, 4.0, 5.0, 7, 7, 7, 7)
graph = b'MSDG' + struct.pack('<BBHIIHH', 1, 1, 2, 2, 0, 1, 1) + struct.pack('<fff', 0.5, 0.5, -0.5) + wall + room
open(f"{d}/graph", 'wb').write(b'\x00' + graph)
desc = b'MSRD' + struct.pack('<BHIIBBf', 1, 2, 3, 2, 2, 3, 12.0) + bytes([10, 20, 30, 40, 50, 60])
open(f"{d}/descriptor", 'wb').write(b'\x01' + desc)
cloud = b'MSRC' + struct.pack('<BBHIIfI', 1, 1, 2, 3, 2, 0.01, 2) + struct.pack('<6h', 1, 2, 3, -4, -5, -6)
open(f"{d}/cloud", 'wb').write(b'\x03' + cloud)
request = b'MSRQ' + struct.pack('<BHHII', 1, 2, 1, 3, 2)
open(f"{d}/request", 'wb').write(b'\x02' + request)
place_request = b'MSPQ' + struct.pack('<BHHIfffI', 1, 2, 1, 3, 4.0, -2.0, 5.0, 0)
open(f"{d}/place_request", 'wb').write(b'\x05' + place_request)
place_cloud = b'MSPC' + struct.pack('<BHHIffffI', 1, 2, 1, 3, 4.0, -2.0, -0.5, 0.04, 2) + bytes([1, 2, 30, 250, 251, 20])
open(f"{d}/place_cloud", 'wb').write(b'\x06' + place_cloud)
PY
cp "$WORK"/collab_messages/* "$WORK/collab_session/"
# Checkpoint seeds: a journal of one odometry record and one two-point scan (shaped records,
# kind byte 1), and a snapshot head with an empty mapper and one session message (kind 0).
python3 - "$WORK/checkpoint_files" <<'PY'
import struct, sys
d = sys.argv[1]
odometry = struct.pack('<8d', 10.0, 1, 2, 3, 0, 0, 0, 1)
scan = struct.pack('<ddI', 9.9, 10.0, 2) + struct.pack('<4H', 1000, 2000, 300, 25000) * 2
rec = lambda t, p: bytes([t]) + struct.pack('<H', len(p)) + p
open(f"{d}/journal", 'wb').write(b'\x01' + rec(1, odometry) + rec(2, scan) + rec(4, b''))
head = struct.pack('<HQI', 1, 3, 7) + struct.pack('<9d', 10.0, 10.0, 0, 0, 0, 0, 0, 0, 1) + struct.pack('<QQ', 0, 0)
session = struct.pack('<I', 1) + bytes([1]) + struct.pack('<I', 3) + b'abc'
open(f"{d}/snapshot", 'wb').write(b'\x00' + head + session)
PY

status=0
for t in "${TARGETS[@]}"; do
  echo "fuzz: $t for ${SECONDS_EACH} s"
  if ! build/fuzz/fuzz/fuzz_"$t" "$WORK/$t" -max_total_time="$SECONDS_EACH" -max_len=70000 \
       -artifact_prefix=build/fuzz/artifacts/"$t"- -print_final_stats=1 > "$WORK/$t.log" 2>&1; then
    echo "fuzz: $t FOUND A PROBLEM:"; tail -40 "$WORK/$t.log"; status=1
  else
    grep -E '^stat::number_of_executed_units|^stat::peak_rss_mb' "$WORK/$t.log" | tr '\n' ' '
    grep -E 'cov: ' "$WORK/$t.log" | tail -1 | sed 's/^/  last: /'
  fi
done
exit $status
