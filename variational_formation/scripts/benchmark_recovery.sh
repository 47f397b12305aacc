#!/usr/bin/env bash
# Crash recovery, measured: a 3000-step hexagon run, unpaced and recorded, in which one agent is
# killed with SIGKILL 20 times (seeded steps, each kill after the previous recovery), against the
# same run without faults. Prints the recovery time (kill -> the respawned agent publishes a step
# it had not published before: median and maximum) and the wall time of both runs. Both runs are
# checked like the fault rostests (every recorded state equals simulate bit for bit).
# usage: ./scripts/benchmark_recovery.sh [kills (default 20)]
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
kills="${1:-20}"
vf_install_dependencies
vf_build
vf_source
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
sed -E 's/^steps:.*/steps: 3000/' "$REPO/config/hexagon.yaml" >"$tmp/hexagon3000.yaml"
run() {  # $1: label, rest: rostest args
  local label="$1"; shift
  rostest variational_formation "$@" >"$tmp/$label.log" 2>&1 || { tail -n 30 "$tmp/$label.log"; echo "$label: failed" >&2; exit 1; }
  echo "$label: $(grep -E 'monitor: [0-9]+ steps in' "$tmp/$label.log" | tail -n 1 | sed -E 's/^.*monitor: //; s/\x1b\[[0-9;]*m//g')"
}
run "no fault" distributed_run.test scenario:="$tmp/hexagon3000.yaml"
run "$kills kills" fault.test fault:=kill_agent kills:="$kills" seed:=11 rate:=0 scenario:="$tmp/hexagon3000.yaml" \
  stats_file:="$tmp/stats"
cat "$tmp/stats"
