#!/usr/bin/env bash
# The transport's ceiling next to the package (README, "Throughput"): benchmark_transport (the
# lockstep message pattern of a nodelet run without maths or protocol, one process, one spinner)
# for each agent count, with the collector on every agent's topic and on one batch topic, each on
# a master of its own (ports 11660-11699).
# usage: benchmark/transport_ceiling.sh [agent counts (default 100 200)]   (after a build in $VF_WS)
source "$(dirname "${BASH_SOURCE[0]}")/../scripts/common.sh"
vf_source
counts=("$@"); [ ${#counts[@]} -eq 0 ] && counts=(100 200)
port=11660
for n in "${counts[@]}"; do
  for collector in topics batch; do
    port=$((port + 1))
    rosmaster --core -p "$port" >/dev/null 2>&1 &
    master=$!
    sleep 1
    ROS_MASTER_URI="http://localhost:$port" timeout 300 "$WS/devel/lib/variational_formation/benchmark_transport" \
      --agents "$n" --steps $(( n <= 100 ? 3000 : 1500 )) --collector "$collector" || echo "benchmark_transport failed ($n agents, $collector)"
    kill "$master" 2>/dev/null; wait "$master" 2>/dev/null
  done
done
