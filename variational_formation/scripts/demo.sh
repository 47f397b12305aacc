#!/usr/bin/env bash
# The main job: installs and builds if needed, runs a scenario (default: the tetrahedron) as a
# distributed ROS run through roslaunch, headless, recording everything rviz would show to
# output/<scenario>.bag, then plots from the bag into output/, prints a summary, and renders the
# bag as rviz shows it to output/<scenario>.mp4 (render_bag.py: Xvfb, rviz and ffmpeg).
# usage: ./scripts/demo.sh [scenario]      (a name in config/ or a path)
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
scenario="${1:-tetrahedron}"
vf_install_dependencies
vf_build
vf_source
out="$ROOT/output"
mkdir -p "$out"
cfg="$REPO/config/$scenario.yaml"
[ -f "$cfg" ] || cfg="$(cd "$(dirname "$scenario")" && pwd)/$(basename "$scenario")"
name="$(basename "$cfg" .yaml)"
echo "running $name: one agent node per agent, the monitor and the recorder (roslaunch, headless)"
# run_formation.sh exits non-zero when the run failed (roslaunch itself exits 0 then).
"$REPO/scripts/run_formation.sh" scenario:="$cfg" record:=true output_dir:="$out" \
  >"$out/$name.launch.log" 2>&1 || { tail -n 20 "$out/$name.launch.log"; echo "demo: the run failed; log: $out/$name.launch.log" >&2; exit 1; }
grep -E "monitor: .*steps in|congruent with" "$out/$name.launch.log" | sed -E 's/^.*\]: //; s/\x1b\[[0-9;]*m//g'
/usr/bin/python3 "$REPO/scripts/plot_bag.py" --bag "$out/$name.bag" --scenario "$cfg" --out-dir "$out" \
  --prefix "$name"
/usr/bin/python3 "$REPO/scripts/render_bag.py" "$out/$name.bag" --out "$out/$name.mp4" || {
  echo "demo: the video could not be rendered (the run, the bag and the plots are fine)" >&2; exit 1; }
echo "bag: $out/$name.bag (replay: rosbag play $out/$name.bag with rviz -d config/formation.rviz)"
