#!/usr/bin/env bash
# The transport's ceiling next to the package (README, "Throughput"): benchmark_transport (the
# lockstep message pattern of a nodelet run without maths or protocol, one process, one spinner)
# for each agent count, with the collector (the monitor's part) on every agent's topic or on one
# batch topic, in the same process or in another one (over TCP, as the monitor), each on a master
# of its own (ports 11660-11699).
# usage: benchmark/transport_ceiling.sh [agent counts (default 100 200)]   (after a build in $VF_WS)
source "$(dirname "${BASH_SOURCE[0]}")/../scripts/common.sh"
vf_source
counts=("$@"); [ ${#counts[@]} -eq 0 ] && counts=(100 200)
port=11660
for n in "${counts[@]}"; do
  for collector in "topics" "batch" "topics --remote" "batch --remote"; do
    port=$((port + 1))
    rosmaster --core -p "$port" >/dev/null 2>&1 &
    master=$!
    sleep 1
    # shellcheck disable=SC2086 # "batch --remote" is two arguments
    ROS_MASTER_URI="http://localhost:$port" timeout 300 "$WS/devel/lib/variational_formation/benchmark_transport" \
      --agents "$n" --steps $(( n <= 100 ? 3000 : 1500 )) --collector $collector ||
      echo "benchmark_transport failed ($n agents, $collector)"
    kill "$master" 2>/dev/null || true
    wait "$master" 2>/dev/null || true
  done
done
