#!/usr/bin/env bash
# Lockstep throughput of the distributed run: for 4, 6, 20 and 50 agents (a ring with the
# chords to the second neighbour, h = 0.005, as fast as possible, no recording), prints the
# steps per second and the real-time factor that the monitor measured from step 0 to the last.
# usage: ./scripts/benchmark_ros.sh [agent counts...]
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
vf_install_dependencies
vf_build
vf_source
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
counts=("$@")
[ ${#counts[@]} -eq 0 ] && counts=(4 6 20 50)
printf '%8s %8s %12s %16s\n' agents steps "steps/s" "real-time factor"
for n in "${counts[@]}"; do
  steps=$(( n <= 6 ? 3000 : (n <= 20 ? 1500 : 600) ))
  /usr/bin/python3 - "$n" "$steps" >"$tmp/ring$n.yaml" <<'PY'
import math, sys
n, steps = int(sys.argv[1]), int(sys.argv[2])
r = n / (2 * math.pi)  # unit sides
print(f"name: ring{n}\ndimension: 2\nkappa: 2.0\ntime_step: 0.005\nsteps: {steps}\nagents:")
for i in range(n):
    a = 2 * math.pi * i / n
    x, y = r * math.cos(a), r * math.sin(a)
    print(f"  - {{id: {i}, initial_position: [{x * 1.05!r}, {y * 0.97!r}], desired_position: [{x!r}, {y!r}]}}")
edges = [[i, (i + k) % n] for i in range(n) for k in (1, 2) if n > 2 * k or (k == 1)]
seen, unique = set(), []
for i, j in edges:
    if (min(i, j), max(i, j)) not in seen and i != j:
        seen.add((min(i, j), max(i, j)))
        unique.append([i, j])
print(f"edges: {unique}")
PY
  roslaunch variational_formation formation.launch scenario:="$tmp/ring$n.yaml" >"$tmp/log$n" 2>&1 || true
  line=$(grep -E "monitor: [0-9]+ steps in" "$tmp/log$n" | sed -E 's/\x1b\[[0-9;]*m//g')
  rate=$(echo "$line" | sed -nE 's/.*: ([0-9]+) steps\/s.*/\1/p')
  rtf=$(echo "$line" | sed -nE 's/.*real-time factor ([0-9.]+).*/\1/p')
  printf '%8s %8s %12s %16s\n' "$n" "$steps" "${rate:-failed}" "${rtf:-failed}"
done
