#!/usr/bin/env bash
# Starts N msgraphs_node processes in heartbeat mode on loopback; each must hear all others.
#   heartbeat_processes_test.sh <msgraphs_node> <N> <domain>
set -u
node=$1; n=$2; domain=$3
logdir=$(mktemp -d); trap 'rm -rf "$logdir"' EXIT
pids=()
for ((r = 1; r <= n; r++)); do
  "$node" --heartbeat --robot-id "$r" --domain "$domain" --loopback \
    --expect-peers $((n - 1)) --duration-s 20 --rate-hz 20 > "$logdir/robot$r.log" 2>&1 &
  pids+=($!)
done
rc=0
for ((r = 1; r <= n; r++)); do
  if ! wait "${pids[r - 1]}"; then rc=1; fi
done
for ((r = 1; r <= n; r++)); do
  echo "--- robot $r"; grep -E "heard|sent|msgraphs_node" "$logdir/robot$r.log"
done
[[ $rc -eq 0 ]] && echo "all $n robots heard each other" || echo "FAILED: some robot did not hear all peers"
exit $rc
