#!/usr/bin/env bash
# Lockstep throughput of two builds of the package in one run (e.g. before and after a change):
# rings of 6 and 50 agents (make_scenario, h = 0.005, no recording), each build in turn, twice,
# each launch with its own master port. Prints the monitor's steps/s and real-time factor.
# usage: benchmark/compare_workspaces.sh OLD_WS NEW_WS [agent counts (default 6 50)]
# environment: VF_COMPARE_ARGS, more formation.launch arguments for both (e.g. nodelet:=true).
set -o pipefail
export PATH="/usr/bin:/bin:$PATH" ROS_HOSTNAME=localhost
old="$1"; new="$2"; shift 2
counts=("$@"); [ ${#counts[@]} -eq 0 ] && counts=(6 50)
tmp="$(mktemp -d)"; trap 'rm -rf "$tmp"' EXIT
port=11640
for n in "${counts[@]}"; do
  steps=$(( n <= 6 ? 3000 : 600 ))
  "$new/devel/lib/variational_formation/make_scenario" --shape ring --agents "$n" --steps "$steps" \
    --name "ring$n" --out "$tmp/ring$n.yaml" || exit 1
done
printf '%6s %8s %6s %10s %6s\n' agents build round "steps/s" rtf
for round in 1 2; do
  for n in "${counts[@]}"; do
    for label in old new; do
      ws=$old; [ "$label" = new ] && ws=$new
      port=$((port + 1))
      line=$( (source "$ws/devel/setup.bash"; export ROS_MASTER_URI=http://localhost:$port
               timeout 300 roslaunch -p $port variational_formation formation.launch scenario:="$tmp/ring$n.yaml" \
                 output_dir:="$tmp" ${VF_COMPARE_ARGS:-} 2>&1) | grep -E "monitor: [0-9]+ steps in" | sed -E 's/\x1b\[[0-9;]*m//g')
      rate=$(echo "$line" | sed -nE 's/.*: ([0-9]+) steps\/s.*/\1/p')
      rtf=$(echo "$line" | sed -nE 's/.*real-time factor ([0-9.]+).*/\1/p')
      printf '%6s %8s %6s %10s %6s\n' "$n" "$label" "$round" "${rate:-failed}" "${rtf:-failed}"
    done
  done
done
