#!/usr/bin/env bash
# README's throughput table in one run: for each agent count, scripts/benchmark_ros.sh with
# nodelets (ring with chords, h = 0.005, no recording) next to the transport's ceiling for the same
# pattern (benchmark_transport: agents in one process, the monitor's part in another over TCP,
# reading one batch per step), and their ratio. Prints a Markdown table.
# usage: benchmark/throughput_table.sh [agent counts (default 100 200)]
source "$(dirname "${BASH_SOURCE[0]}")/../scripts/common.sh"
vf_install_dependencies
vf_build
vf_source
counts=("$@"); [ ${#counts[@]} -eq 0 ] && counts=(100 200)
rows=()
port=11690
for n in "${counts[@]}"; do
  package=$(VF_BENCH_MODES=nodelet "$REPO/scripts/benchmark_ros.sh" "$n" 2>/dev/null |
            awk -v n="$n" '$1 == n && $2 == "nodelet" { print $4; exit }')
  port=$((port + 1))
  rosmaster --core -p "$port" >/dev/null 2>&1 &
  master=$!
  sleep 1
  ceiling=$(ROS_MASTER_URI="http://localhost:$port" timeout 300 "$WS/devel/lib/variational_formation/benchmark_transport" \
              --agents "$n" --steps $(( n <= 100 ? 3000 : 1500 )) --collector batch --remote 2>/dev/null |
            sed -nE 's/.* ([0-9]+) steps\/s$/\1/p')
  kill "$master" 2>/dev/null || true
  wait "$master" 2>/dev/null || true
  ratio=$(awk -v a="${package:-0}" -v b="${ceiling:-0}" 'BEGIN { if (a > 0 && b > 0) printf "%.2f", a / b; else print "n/a" }')
  rows+=("| $n | ${package:-failed} | ${ceiling:-failed} | $ratio |")
done
echo "| agents | steps/s (nodelets) | transport ceiling, steps/s | ratio |"
echo "| --- | --- | --- | --- |"
printf '%s\n' "${rows[@]}"
