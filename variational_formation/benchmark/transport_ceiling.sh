#!/usr/bin/env bash
# The transport's ceiling next to the package (README, "Throughput"): benchmark_transport (the
# lockstep message pattern of a nodelet run without maths or protocol, in one process) for each
# agent count and each delivery (manager: an agent_manager's own transport, the default; local:
# the exchange through roscpp's global queue; roscpp: every state on its topic), with the
# collector (the monitor's part) on every agent's topic or on one batch topic, in the same process
# or in another one (over TCP, as the monitor), on a master of the script's own (a free port in
# 11660-11699).
# usage: benchmark/transport_ceiling.sh [agent counts (default 100 200)]   (after a build in $VF_WS)
# environment: VF_CEILING_DELIVERIES (default "manager local roscpp"): the deliveries to run.
source "$(dirname "${BASH_SOURCE[0]}")/../scripts/common.sh"
vf_source
counts=("$@"); [ ${#counts[@]} -eq 0 ] && counts=(100 200)
port="$(vf_free_port 11660 40)" || exit 1
rosmaster --core -p "$port" >/dev/null 2>&1 &
master=$!
trap 'kill "$master" 2>/dev/null || true; wait "$master" 2>/dev/null || true' EXIT
sleep 1
for n in "${counts[@]}"; do
  for delivery in ${VF_CEILING_DELIVERIES:-manager local roscpp}; do
    for collector in "topics" "batch" "topics --remote" "batch --remote"; do
      # shellcheck disable=SC2086 # "batch --remote" is two arguments
      ROS_MASTER_URI="http://localhost:$port" timeout 300 "$WS/devel/lib/variational_formation/benchmark_transport" \
        --agents "$n" --steps $(( n <= 100 ? 3000 : 1500 )) --collector $collector --delivery "$delivery" ||
        echo "benchmark_transport failed ($n agents, $collector, $delivery delivery)"
    done
  done
done
