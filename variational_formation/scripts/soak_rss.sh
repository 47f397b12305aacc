#!/usr/bin/env bash
# Runs an unbounded formation (the scenario with steps: 0) at full speed, without recording, and
# prints the resident memory (RSS, MiB) of every node once a minute, then stops the run.
# Memory that stays flat shows that nothing grows with the number of steps.
# usage: ./scripts/soak_rss.sh [scenario (default hexagon)] [seconds (default 600)] [port (default 11611)]
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
scenario="${1:-hexagon}"
seconds="${2:-600}"
port="${3:-11611}"
vf_install_dependencies
vf_build
vf_source
tmp="$(mktemp -d)"
cfg="$REPO/config/$scenario.yaml"
[ -f "$cfg" ] || cfg="$scenario"
sed -E 's/^steps:.*/steps: 0/' "$cfg" >"$tmp/soak.yaml"
export ROS_MASTER_URI="http://localhost:$port"
roslaunch -p "$port" variational_formation formation.launch scenario:="$tmp/soak.yaml" output_dir:="$tmp" \
  >"$tmp/launch.log" 2>&1 &
launch=$!
trap 'kill -INT $launch 2>/dev/null; wait $launch 2>/dev/null; rm -rf "$tmp"' EXIT
sleep 5
pids() { pgrep -P "$launch" -f "__name:=(agent_[0-9]+|monitor)" ; }  # this launch's nodes only
names=()
for pid in $(pids); do names+=("$(tr '\0' ' ' </proc/"$pid"/cmdline | grep -oE '__name:=[a-z_0-9]+' | cut -d= -f2)"); done
printf '%8s %10s' minute step; printf ' %9s' "${names[@]}"; echo
for ((t = 0; t <= seconds; t += 60)); do
  [ "$t" -gt 0 ] && sleep 60
  step=$(rostopic echo -n 1 /formation/status/step 2>/dev/null | head -n 1)
  printf '%8d %10s' $((t / 60)) "${step:-?}"
  for pid in $(pids); do printf ' %9.1f' "$(awk '/VmRSS/ {print $2 / 1024}' /proc/"$pid"/status)"; done
  echo
done
