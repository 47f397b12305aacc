#!/usr/bin/env bash
# Runs formation.launch, or robots.launch with launch:=robots, and tells a good run from a
# failed one: roslaunch itself exits 0 even when a required node failed, so this reads the
# result file the monitor writes (output_dir/<name>.result.yaml). Exit status 0 only if the run
# succeeded (or an unbounded run was stopped); otherwise 1, with the monitor's reason, or
# roslaunch's own status if no result was written (a bad argument or scenario stops the launch
# before the monitor runs); 2 for a launch:= other than formation or robots.
# usage: run_formation.sh [launch:=formation|robots] [roslaunch args...] scenario:=S [output_dir:=DIR] [other args of the launch file]
set -uo pipefail
case "${1:-}" in
  -h|--help) sed -n '2,/^# usage/p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
esac
launch=formation
args=()
for a in "$@"; do
  case "$a" in
    launch:=*) launch="${a#launch:=}" ;;
    *) args+=("$a") ;;
  esac
done
# Each launch file's own default scenario.
case "$launch" in
  formation) scenario=tetrahedron ;;
  robots) scenario=hexagon ;;
  *) echo "run_formation: launch: expected formation or robots, got '$launch'" >&2; exit 2 ;;
esac
output_dir="$HOME/.ros"
for a in "${args[@]}"; do
  case "$a" in
    scenario:=*) scenario="${a#scenario:=}" ;;
    output_dir:=*) output_dir="${a#output_dir:=}" ;;
  esac
done
name="$(basename "$scenario" .yaml)"
# Under ROS_NAMESPACE=a/b the formation is /a/b/formation and its files start with "a_b_".
ns="${ROS_NAMESPACE:-}"; ns="${ns#/}"; ns="${ns%/}"; prefix="${ns//\//_}"
result="$output_dir/${prefix:+${prefix}_}$name.result.yaml"
rm -f "$result"
roslaunch variational_formation "$launch.launch" "${args[@]}"
status=$?
if [ ! -f "$result" ]; then
  echo "run_formation: the run failed before the monitor started (roslaunch exit status $status; see above)" >&2
  [ "$status" -ne 0 ] && exit "$status" || exit 1
fi
# A field of the result file, as YAML reads it (its strings are quoted and escaped).
field() {
  /usr/bin/python3 -c 'import sys, yaml; v = (yaml.safe_load(open(sys.argv[1])) or {}).get(sys.argv[2]); print("" if v is None else v)' \
    "$result" "$1" 2>/dev/null || echo "(unreadable result file $result)"
}
outcome="$(field result)"
formation="$(field formation)"
case "$outcome" in
  succeeded|stopped)
    # Only "converged to the desired shape ..." is converged; every other verdict starts "not
    # converged" (its mirror image, folded, still settling, an edge off, blocked).
    case "$formation" in
      "not converged"*) why="${formation#not converged}"; why="${why#: }"; why="${why# }"
        echo "run_formation: the run $outcome, but the formation did not converge: $why" >&2 ;;
    esac
    exit 0 ;;
  *) echo "run_formation: the run $outcome: $(field reason)" >&2; exit 1 ;;
esac
