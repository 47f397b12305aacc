#!/usr/bin/env bash
# Region-of-attraction throughput: Google Benchmark figures (hexagon campaign of 3025
# simulations on 1 and 2 threads, plain loops with vi/euler/rk4, scaling with agents and
# edges), then a 1000 x 1000 map (one million simulations of 200 steps) through the roa CLI.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
vf_install_dependencies
vf_build
vf_source
bin="$WS/devel/lib/variational_formation"
"$bin/benchmark_roa" --benchmark_min_time=0.5
out="$(mktemp -d)"
"$bin/roa" --scenario "$REPO/config/hexagon.yaml" --agent 1 --x-range -8 8 --y-range -8 8 \
  --resolution 1000 1000 --time-step 0.014 --kappa 13 --steps 200 --out "$out/roa_1000.csv"
rm -rf "$out"
