#!/usr/bin/env bash
# Throughput and cost of the distributed lockstep run, as one table: agent count x mode.
#   process: one process per agent (formation.launch scenario:=FILE)
#   nodelet: every agent in one nodelet manager, agent_manager (formation.launch scenario:=FILE nodelet:=true);
#            n/a while the launch file has no `nodelet` argument or its launch fails.
#   sharded: the agents split into VF_BENCH_SHARDS (default 5) agent_managers of consecutive ids,
#            each written by make_agents_launch.py as for a machine of doc/distributed.md,
#            "Sharded managers", all on this machine; formation.launch agents:=false takes their
#            batches (agent_manager:=those managers).
# Each run is a ring with chords to the second neighbour written by make_scenario (spacing 1 m,
# start perturbed by up to 0.05 m per coordinate, seed 1, kappa 2, h = 0.005 s; above the 2000
# agents make_scenario writes, the same layout from benchmark/simulate_scaling.py), run as fast
# as possible without recording, on its own ROS master (a free port in 11500-11599).
# Columns:
#   steps/s, real-time factor: the monitor's final line, from step 0 to the last step;
#   CPU%/agent: CPU time of the processes hosting agents (`agent` and `agent_manager` processes under
#     the launch, from /proc every VF_BENCH_SAMPLE s) over the monitor's stepping window,
#     divided by the window and the agent count (100 = one core);
#   RSS MiB/agent: the largest total resident memory of those processes, divided by the agent
#     count;
#   start s: from roslaunch's start to the monitor's step 0 (every agent loaded, recovered and
#     heard);
#   exact: with VF_BENCH_RECORD=1 the run is recorded (record:=true, so the figures are the
#     recorded throughput) and benchmark/bag_vs_simulate.py compares every state of the bag with
#     simulate, bit for bit: yes or no; "-" without recording.
# usage: ./scripts/benchmark_ros.sh [agent counts...]          (default 6 20 50 100 200)
# environment: VF_BENCH_MODES (default "process nodelet"; also sharded), VF_BENCH_SHARDS (default 5), VF_BENCH_STEPS (steps per run;
#   default max(600, 120000 / agents), about 10-40 s per run), VF_BENCH_TIMEOUT (s per run,
#   default 900), VF_BENCH_SAMPLE (s between samples, default 0.5), VF_BENCH_RECORD (1: record and
#   check exactness; default 0), VF_BENCH_PORT_BASE and VF_BENCH_PORTS (the masters' port range,
#   default 11500 and 100), VF_BENCH_MAKE_FLAGS (more make_scenario flags, e.g. "--safety 0.25 1 0.2"),
#   VF_BENCH_ARGS (more formation.launch arguments, e.g. "rate:=1": a paced run), VF_BENCH_KEEP (1: keep
#   the temporary folder with the scenarios, launch logs and bags).
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
vf_install_dependencies
vf_build
vf_source
tmp="$(mktemp -d)"
# VF_BENCH_KEEP=1 keeps the scenarios, launch logs and bags for a look afterwards.
trap 'if [ "${VF_BENCH_KEEP:-0}" = 1 ]; then echo "benchmark_ros: kept $tmp" >&2; else rm -rf "$tmp"; fi' EXIT
counts=("$@")
[ ${#counts[@]} -eq 0 ] && counts=(6 20 50 100 200)
read -r -a modes <<<"${VF_BENCH_MODES:-process nodelet}"
timeout_s="${VF_BENCH_TIMEOUT:-900}"
sample_s="${VF_BENCH_SAMPLE:-0.5}"
record="${VF_BENCH_RECORD:-0}"
monitor_line='monitor: [0-9]+ steps in'

# Every VF_BENCH_SAMPLE s until the launch ends or the monitor's final line is in the log:
# "S <time>" then "P <pid> <utime+stime ticks> <rss KiB>" per agent-hosting process under
# root; "E <time>" when it stops.
sample_agents() {
  local root="$1" log="$2" out="$3" page_kib pids
  page_kib=$(( $(getconf PAGESIZE) / 1024 ))
  while kill -0 "$root" 2>/dev/null && ! grep -qE "$monitor_line" "$log"; do
    pids=$(ps -e -o pid=,ppid=,comm= | awk -v root="$root" '
      { parent[$1] = $2; name[$1] = $3 }
      END {
        for (p in parent) {
          q = p
          while (q in parent && q != root && q > 1) q = parent[q]
          if (q == root && p != root && name[p] ~ /^(agent|nodelet|agent_manager)$/) printf "/proc/%s/stat ", p
        }
      }')
    echo "S $EPOCHREALTIME" >>"$out"
    # shellcheck disable=SC2086
    [ -n "$pids" ] && cat $pids 2>/dev/null | awk -v kib="$page_kib" '
      { pid = $1; sub(/^.*\) /, ""); print "P", pid, $12 + $13, $22 * kib }' >>"$out"
    sleep "$sample_s"
  done
  echo "E $EPOCHREALTIME" >>"$out"
}

# CPU%/agent and RSS MiB/agent from the samples, the stepping seconds, the agent count and
# the wall time of the last step (the monitor line's time stamp; if empty, when sampling
# stopped). The CPU window is the samples within the stepping seconds before that.
summarise_samples() {
  awk -v seconds="$2" -v n="$3" -v end="$4" -v hz="$(getconf CLK_TCK)" '
    function flush() { if (k) { c = 0; for (p in ticks) c += ticks[p]; cum[k] = c } }
    $1 == "S" { flush(); k++; t[k] = $2; rss[k] = 0; next }
    $1 == "P" { ticks[$2] = $3; rss[k] += $4; next }
    $1 == "E" && !end { end = $2 }
    END {
      flush()
      peak = 0
      for (i = 1; i <= k; i++) if (rss[i] > peak) peak = rss[i]
      first = 0; last = 0
      for (i = 1; i <= k; i++) {
        if (end && t[i] >= end - seconds && !first) first = i
        if (end && t[i] < end) last = i
      }
      cpu = "-"
      if (first && last > first && t[last] - t[first] >= 0.25 * seconds) cpu = sprintf("%.1f", 100 * (cum[last] - cum[first]) / hz / (t[last] - t[first]) / n)
      printf "%s %s\n", cpu, (peak > 0 ? sprintf("%.1f", peak / 1024 / n) : "-")
    }' "$1"
}

mode_supported() {
  [ "$1" = process ] && return 0
  # grep reads it all (not -q): under pipefail, roslaunch killed by SIGPIPE would fail the test.
  roslaunch --ros-args variational_formation formation.launch 2>/dev/null | grep -E "^ +$1[ :(]" >/dev/null
}

# The launch file of a sharded run (mode sharded): VF_BENCH_SHARDS managers of consecutive ids,
# each one make_agents_launch.py writes, and formation.launch without agents over their batches.
# Its arguments (scenario, record, ...) go to formation.launch. Prints its path.
sharded_launch() {
  local scenario="$1" n="$2" dir="$3" shards="${VF_BENCH_SHARDS:-5}" k managers=""
  mkdir -p "$dir"
  for ((k = 0; k < shards; k++)); do managers+="${managers:+ }manager_$k"; done
  {
    echo "<launch>"
    echo '  <arg name="scenario"/>'
    echo '  <arg name="record" default="false"/>'
    echo '  <arg name="record_max_size" default="0"/>'
    echo '  <arg name="output_dir" default="$(env HOME)/.ros/vf_output"/>'
    for ((k = 0; k < shards; k++)); do
      rosrun variational_formation make_agents_launch.py --scenario "$scenario" --nodelet true \
        --ids "$((k * n / shards))-$(((k + 1) * n / shards - 1))" --manager-name "manager_$k" \
        --agent-manager "$managers" --out "$dir/shard_$k.launch" >/dev/null
      echo "  <include file=\"$dir/shard_$k.launch\"/>"
    done
    echo '  <include file="$(find variational_formation)/launch/formation.launch">'
    echo '    <arg name="scenario" value="$(arg scenario)"/>'
    echo '    <arg name="agents" value="false"/>'
    echo "    <arg name=\"agent_manager\" value=\"$managers\"/>"
    echo '    <arg name="record" value="$(arg record)"/>'
    echo '    <arg name="record_max_size" value="$(arg record_max_size)"/>'
    echo '    <arg name="output_dir" value="$(arg output_dir)"/>'
    echo "  </include>"
    echo "</launch>"
  } >"$dir/sharded.launch"
  echo "$dir/sharded.launch"
}

declare -A skip
for m in "${modes[@]}"; do
  case "$m" in process|nodelet|sharded) ;; *) echo "benchmark_ros: VF_BENCH_MODES: unknown mode '$m' (process, nodelet, sharded)" >&2; exit 2 ;; esac
  [ "$m" = sharded ] || mode_supported "$m" || { skip[$m]=1; echo "benchmark_ros: formation.launch has no '$m' argument: $m is n/a" >&2; }
done

row() { printf '%7s %-8s %7s %9s %17s %11s %14s %8s %6s\n' "$@"; }
row agents mode steps "steps/s" "real-time factor" "CPU%/agent" "RSS MiB/agent" "start s" exact
for n in "${counts[@]}"; do
  steps="${VF_BENCH_STEPS:-$(( 120000 / n > 600 ? 120000 / n : 600 ))}"
  scenario="$tmp/ring$n.yaml"
  if [ "$n" -le 2000 ]; then
    rosrun variational_formation make_scenario --shape ring --agents "$n" --perturb 0.05 --seed 1 \
      --steps "$steps" --name "ring$n" --out "$scenario" ${VF_BENCH_MAKE_FLAGS:-}
  else
    PYTHONPATH="$(dirname "${BASH_SOURCE[0]}")/../benchmark" python3 -c \
      "import sys, simulate_scaling; sys.stdout.write(simulate_scaling.ring_yaml($n, $steps))" >"$scenario"
  fi
  for m in "${modes[@]}"; do
    if [ -n "${skip[$m]:-}" ]; then
      row "$n" "$m" "$steps" n/a n/a n/a n/a n/a n/a
      continue
    fi
    port="$(vf_free_port "${VF_BENCH_PORT_BASE:-11500}" "${VF_BENCH_PORTS:-100}")"
    log="$tmp/log_${m}_$n" samples="$tmp/samples_${m}_$n"
    : >"$samples"
    extra=()
    [ "$m" = nodelet ] && extra=(nodelet:=true)
    read -r -a more <<<"${VF_BENCH_ARGS:-}"
    extra+=("${more[@]}")
    # No size limit: 600 steps of 1000 agents with their markers make about 1.8 GB.
    [ "$record" = 1 ] && extra+=(record:=true record_max_size:=0 output_dir:="$tmp/out_${m}_$n")
    target=(variational_formation formation.launch)
    [ "$m" = sharded ] && target=("$(sharded_launch "$scenario" "$n" "$tmp/sharded_$n")")
    launched=$EPOCHREALTIME
    ROS_MASTER_URI="http://localhost:$port" ROS_LOG_DIR="$tmp/ros_log" \
      timeout -s INT -k 30 "$timeout_s" \
      roslaunch -p "$port" "${target[@]}" scenario:="$scenario" "${extra[@]}" \
      >"$log" 2>&1 &
    launch=$!
    sample_agents "$launch" "$log" "$samples" &
    sampler=$!
    wait "$launch" || true
    wait "$sampler" || true
    line=$(grep -E "$monitor_line" "$log" | sed -E 's/\x1b\[[0-9;]*m//g' | tail -n 1 || true)
    rate=$(echo "$line" | sed -nE 's/.*: ([0-9]+) steps\/s.*/\1/p')
    rtf=$(echo "$line" | sed -nE 's/.*real-time factor ([0-9.]+).*/\1/p')
    seconds=$(echo "$line" | sed -nE 's/.* steps in ([0-9.]+) s.*/\1/p')
    ended=$(echo "$line" | sed -nE 's/.*\[([0-9]+\.[0-9]+)(, [0-9.]+)?\]: monitor: .*/\1/p')
    if [ -z "$rate" ]; then
      reason=$(sed -E 's/\x1b\[[0-9;]*m//g' "$log" | grep -iE 'error|fatal|exited|timeout' | tail -n 1 || true)
      echo "benchmark_ros: $m, $n agents: no monitor line, so $m is n/a from here (${reason:-see the launch output})" >&2
      skip[$m]=1
      row "$n" "$m" "$steps" n/a n/a n/a n/a n/a n/a
      continue
    fi
    read -r cpu rss < <(summarise_samples "$samples" "$seconds" "$n" "$ended")
    start=-
    [ -n "$ended" ] && start=$(awk -v e="$ended" -v s="$seconds" -v l="$launched" 'BEGIN { printf "%.1f", e - s - l }')
    exact=-
    if [ "$record" = 1 ]; then
      exact=no
      python3 "$(dirname "${BASH_SOURCE[0]}")/../benchmark/bag_vs_simulate.py" "$scenario" "$tmp/out_${m}_$n/ring$n.bag" >&2 && exact=yes
      rm -rf "$tmp/out_${m}_$n"
    fi
    row "$n" "$m" "$steps" "$rate" "$rtf" "$cpu" "$rss" "$start" "$exact"
  done
done
