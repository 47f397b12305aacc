#!/usr/bin/env bash
# Where the time of a nodelet run goes: one ring formation (make_scenario) per agent count, all
# agents in formation/manager, run as fast as possible on its own ROS master (a free port in
# 11600-11649, or VF_PROFILE_PORT_BASE and the 50 above it; 800000 / n steps, about 20-30 s). While it runs, `perf record` samples the manager and the monitor for
# VF_PROFILE_SECONDS (default 5) s (and the recorder, with record:=true), and the script prints
# for each:
#   - its share of the machine's CPU over that window (100 = one core), from /proc;
#   - perf's split of its samples by library: kernel, roscpp (roscpp, serialisation, xmlrpc,
#     rosconsole, cpp_common), libc/libstdc++ (locks, allocation), tf2, the package's ROS layer,
#     the package's core (the maths), other.
# VF_PROFILE_STEPS sets the steps of every run (a loaded machine needs more).
# VF_PROFILE_SYMBOLS=N also prints each process's N functions with the most samples.
# With extra launch arguments after "--" (e.g. -- record:=true marker_every:=10) they are added
# to every run.
# usage: ./scripts/profile_ros.sh [agent counts...] [-- formation.launch args...]   (default 50 100)
# Needs perf (linux-perf); without it only the CPU shares are printed.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
vf_install_dependencies
vf_build
vf_source
counts=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do counts+=("$1"); shift; done
[ "${1:-}" = "--" ] && shift
extra=("$@")
[ ${#counts[@]} -eq 0 ] && counts=(50 100)
seconds="${VF_PROFILE_SECONDS:-5}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
hz="$(getconf CLK_TCK)"


# utime + stime of a process, in clock ticks.
ticks() { awk '{ sub(/^.*\) /, ""); print $12 + $13 }' "/proc/$1/stat" 2>/dev/null || echo 0; }

split_by_library() {
  perf report -i "$1" --no-children --sort dso -g none --percent-limit 0 2>/dev/null | awk '
    /^ *[0-9.]+%/ {
      p = $1; sub(/%/, "", p); d = $2
      if (d ~ /kernel/) k = "kernel"
      else if (d ~ /roscpp|xmlrpc|rosconsole|cpp_common|rostime/) k = "roscpp"
      else if (d ~ /^libc\.|libstdc|libpthread|libm\./) k = "libc/libstdc++"
      else if (d ~ /tf2/) k = "tf2"
      else if (d ~ /variational_formation_core/) k = "core (maths)"
      else if (d ~ /rosbag|roslz4|bz2|lz4/) k = "rosbag"
      else if (d ~ /variational_formation|agent_manager|^monitor$|^recorder$/) k = "ROS layer"
      else k = "other"
      share[k] += p
    }
    END { for (k in share) printf "    %-16s %5.1f%%\n", k, share[k] }' | sort -k2 -t'%' -rn
}

for n in "${counts[@]}"; do
  steps=${VF_PROFILE_STEPS:-$(( 800000 / n ))}
  scenario="$tmp/ring$n.yaml"
  rosrun variational_formation make_scenario --shape ring --agents "$n" --perturb 0.05 --seed 1 \
    --steps "$steps" --name "ring$n" --out "$scenario"
  port="$(vf_free_port "${VF_PROFILE_PORT_BASE:-11600}" 50)"
  log="$tmp/log$n"
  ROS_MASTER_URI="http://localhost:$port" ROS_LOG_DIR="$tmp/ros_log" \
    timeout -s INT -k 30 600 roslaunch -p "$port" variational_formation formation.launch \
    scenario:="$scenario" nodelet:=true output_dir:="$tmp/out" "${extra[@]}" >"$log" 2>&1 &
  launch=$!
  # Until the monitor says RUNNING (roslaunch's output to a file comes late), then a second more.
  started=$EPOCHREALTIME
  for _ in $(seq 1 240); do
    state=$(ROS_MASTER_URI="http://localhost:$port" timeout 5 rostopic echo -n 1 /formation/progress/state 2>/dev/null | head -n 1 || true)
    [ "$state" = 1 ] && break
    sleep 0.5
  done
  awk -v s="$started" -v e="$EPOCHREALTIME" -v n="$n" 'BEGIN { printf "profile_ros: %s agents: running %.1f s after the launch\n", n, e - s }'
  sleep 1
  # The manager and the monitor, and the recorder with record:=true.
  names=() pids=()
  # Among this launch's own processes (others may run formations on the same machine), by
  # executable and node name (a node's remappings come between them).
  for spec in "manager:/agent_manager .*__name:=manager" "monitor:/monitor .*__name:=monitor" \
              "recorder:/recorder .*__name:=recorder"; do
    pid=$(ps -e -o pid=,ppid=,args= | awk -v root="$launch" -v pattern="${spec#*:}" '
      { parent[$1] = $2; line[$1] = $0 }
      END {
        for (p in parent) {
          q = p
          while (q in parent && q != root && q > 1) q = parent[q]
          if (q == root && line[p] ~ pattern) { print p; exit }
        }
      }' || true)
    if [ -n "$pid" ]; then names+=("${spec%%:*}"); pids+=("$pid"); fi
  done
  if [ "${names[0]:-}" != manager ] || [ "${names[1]:-}" != monitor ]; then
    echo "profile_ros: $n agents: the manager or the monitor is not running; see the launch output:" >&2
    tail -n 20 "$log" >&2
    kill -INT "$launch" 2>/dev/null; wait "$launch"
    exit 1
  fi
  before=() t0=$EPOCHREALTIME
  for pid in "${pids[@]}"; do before+=("$(ticks "$pid")"); done
  if command -v perf >/dev/null; then
    for k in "${!pids[@]}"; do
      perf record -q -F 499 -g -p "${pids[$k]}" -o "$tmp/${names[$k]}.data" -- sleep "$seconds" >/dev/null 2>&1 &
    done
    wait $(jobs -p | grep -v "^$launch$") 2>/dev/null || true
  else
    sleep "$seconds"
  fi
  cpu="" t1=$EPOCHREALTIME
  for k in "${!pids[@]}"; do
    cpu+=$(awk -v a="${before[$k]}" -v b="$(ticks "${pids[$k]}")" -v s="$t0" -v e="$t1" -v hz="$hz" -v name="${names[$k]}" \
      'BEGIN { printf "%s%s %.0f", (name == "manager" ? "" : ", "), name, 100 * (b - a) / hz / (e - s) }')
  done
  wait "$launch" 2>/dev/null
  rate=$(sed -E 's/\x1b\[[0-9;]*m//g' "$log" | grep -oE '[0-9]+ steps/s' | tail -n 1)
  echo "== $n agents (ring with chords, nodelet:=true ${extra[*]}): ${rate:-no final line} over the run, ${seconds} s sampled"
  echo "  CPU (100 = one core): $cpu"
  for name in "${names[@]}"; do
    [ -f "$tmp/$name.data" ] || continue
    echo "  $name$([ "$name" = manager ] && echo " (all $n agents)"), samples by library:"
    split_by_library "$tmp/$name.data"
    if [ "${VF_PROFILE_SYMBOLS:-0}" -gt 0 ]; then
      echo "  $name, the ${VF_PROFILE_SYMBOLS} functions with the most samples (self):"
      perf report -i "$tmp/$name.data" --no-children --sort sym -g none --percent-limit 0.5 2>/dev/null |
        grep -E '^ +[0-9.]+%' | head -n "$VF_PROFILE_SYMBOLS" | sed -E 's/^ +/    /'
    fi
    rm -f "$tmp/$name.data"
  done
done
