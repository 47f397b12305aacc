#!/usr/bin/env bash
# The safety filter's cost in lockstep (doc/distributed.md, "Sensing"): scripts/benchmark_ros.sh
# with nodelets (ring with chords, h = 0.005 s, no recording) for each agent count, without and
# with `--safety 0.25 1 0.2` (r = 0.25 m, R = 1 m, gamma = 0.2), and their ratio. Target at 1000
# agents: safety on >= 0.5 x off. Prints a Markdown table.
# usage: benchmark/safety_throughput.sh [agent counts (default 1000)]
source "$(dirname "${BASH_SOURCE[0]}")/../scripts/common.sh"
counts=("$@"); [ ${#counts[@]} -eq 0 ] && counts=(1000)
rate() {  # steps/s of one nodelet run of $1 agents, with make_scenario flags $2
  VF_BENCH_MODES=nodelet VF_BENCH_MAKE_FLAGS="$2" "$REPO/scripts/benchmark_ros.sh" "$1" |
    awk -v n="$1" '$1 == n && $2 == "nodelet" { print $4; exit }'
}
echo "| agents | steps/s, safety off | steps/s, safety on | on / off |"
echo "| --- | --- | --- | --- |"
for n in "${counts[@]}"; do
  off=$(rate "$n" "")
  on=$(rate "$n" "--safety 0.25 1 0.2")
  ratio=$(awk -v a="${on:-0}" -v b="${off:-0}" 'BEGIN { if (a > 0 && b > 0) printf "%.2f", a / b; else print "n/a" }')
  echo "| $n | ${off:-failed} | ${on:-failed} | $ratio |"
done
