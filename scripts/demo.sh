#!/usr/bin/env bash
# The main job: installs and builds if needed, runs the tetrahedron scenario, writes CSVs and
# plots into output/ and prints a summary.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
scenario="${1:-tetrahedron}"
vf_install_dependencies
vf_build
vf_source
out="$REPO/output"
mkdir -p "$out"
cfg="$REPO/config/$scenario.yaml"
[ -f "$cfg" ] || cfg="$scenario"
rosrun variational_formation simulate --scenario "$cfg" \
  --out "$out/$scenario.traj.csv" --metrics "$out/$scenario.metrics.csv"
/usr/bin/python3 "$REPO/scripts/plot_simulation.py" --scenario "$cfg" \
  --traj "$out/$scenario.traj.csv" --metrics "$out/$scenario.metrics.csv" \
  --out-dir "$out" --prefix "$scenario"
