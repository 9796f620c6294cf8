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
[ ${#TARGETS[@]} -eq 0 ] && TARGETS=(velodyne_decoder pcap_reader candump_parser can_decoder)
DATA=${MSGRAPHS_DATA_DIR:-$(pwd)/../shared/data}

cmake --preset fuzz >/dev/null
cmake --build --preset fuzz >/dev/null

WORK=$(mktemp -d); trap 'rm -rf "$WORK"' EXIT
mkdir -p build/fuzz/artifacts
mkdir -p "$WORK"/{velodyne_decoder,pcap_reader,candump_parser,can_decoder}
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
