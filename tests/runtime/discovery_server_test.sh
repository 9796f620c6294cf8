#!/usr/bin/env bash
# Discovery through a Fast DDS Discovery Server (`fastdds discovery`, fastdds-tools), as on a
# radio that carries no multicast: two robots' nodes are its clients and must hear each other.
#   discovery_server_test.sh <msgraphs_node> <port>
set -u
node=$1; port=$2
# fastdds-tools' server binary; `fastdds discovery` is a wrapper that would leave it running
# when killed.
server_bin=$(command -v fast-discovery-server) ||
  { echo "SKIPPED: fast-discovery-server (fastdds-tools) is not installed"; exit 77; }
log=$(mktemp -d); server=""; trap '[[ -n $server ]] && kill $server 2>/dev/null; rm -rf "$log"' EXIT
# Without the server the clients must not find each other: discovery goes through it alone.
"$node" --heartbeat --robot-id 1 --loopback --discovery-server "127.0.0.1:$port" --duration-s 3 > /dev/null 2>&1 &
lone=$!
if "$node" --heartbeat --robot-id 2 --loopback --discovery-server "127.0.0.1:$port" --expect-peers 1 \
     --duration-s 3 > /dev/null 2>&1; then
  echo "FAIL: the clients found each other without the server (multicast still on?)"; exit 1
fi
wait $lone
echo "without the server: the clients do not find each other (as expected)"
"$server_bin" -i 0 -l 127.0.0.1 -p "$port" > "$log/server.log" 2>&1 &
server=$!
pids=()
for r in 1 2; do
  "$node" --heartbeat --robot-id "$r" --loopback --discovery-server "127.0.0.1:$port" \
    --expect-peers 1 --duration-s 20 --rate-hz 10 > "$log/robot$r.log" 2>&1 &
  pids+=($!)
done
rc=0
for p in "${pids[@]}"; do wait "$p" || rc=1; done
cat "$log"/robot*.log | grep -E "heard|sent|msgraphs_node"
[[ $rc -eq 0 ]] && echo "PASS: both clients of the Discovery Server heard each other" || { cat "$log/server.log"; echo FAIL; }
exit $rc
