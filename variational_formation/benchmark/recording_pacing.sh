#!/usr/bin/env bash
# What recording and pacing cost a nodelet run, as ratios measured in one run (issue 34's
# targets), printed as two Markdown tables. Every run is scripts/benchmark_ros.sh's (a ring with
# chords to the second neighbour, all agents in one manager, nodelet:=true, its own ROS master).
#
# Recording, per agent count of VF_RP_RECORD (default "100 1000"), h = 0.005 s, max(1200,
# 1.2e6 / agents) steps (VF_BENCH_STEPS overrides): the same scenario unrecorded, then recorded
# (record:=true, no size limit) and compared with simulate by benchmark/bag_vs_simulate.py, in
# VF_RP_ROUNDS rounds (default 3), each an unrecorded run then a recorded one. The row gives the
# medians of each column and of the rounds' ratios, over the rounds that gave a figure (one round's
# ratio moves by +-15 % on a 2-core VM); the rounds follow the table. Exact only if every recorded
# run was.
# Target: recorded steps/s >= 0.5 x unrecorded (the median ratio), exact.
#
# Pacing, per agent count of VF_RP_PACE (default "100 500"): an unpaced run at h = 0.005 s gives
# its rate R0; the time step is then chosen so that real time needs R0 / VF_RP_MARGIN steps/s
# (h = VF_RP_MARGIN / R0, margin default 1.3), and that scenario runs unpaced, then at rate:=1.
# Both runs last VF_RP_SECONDS (default 10) of simulated time. Target: where the unpaced
# real-time factor is >= 1.2, the paced run keeps real time: its simulated time over its wall time
# (from step 0 to the last step) is >= 0.98.
#
# usage: benchmark/recording_pacing.sh
# environment: VF_RP_RECORD, VF_RP_PACE, VF_RP_MARGIN, VF_RP_ROUNDS as above; VF_BENCH_STEPS (steps per
#   recording run, default as above); VF_BENCH_ARGS (more formation.launch arguments, e.g.
#   "record_compression:=none"); masters on ports 11600-11699
#   (VF_BENCH_PORT_BASE, VF_BENCH_PORTS).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
source "$here/../scripts/common.sh"
export VF_BENCH_MODES=nodelet VF_BENCH_PORT_BASE="${VF_BENCH_PORT_BASE:-11600}" VF_BENCH_PORTS="${VF_BENCH_PORTS:-100}"
read -r -a record_counts <<<"${VF_RP_RECORD:-100 1000}"
read -r -a pace_counts <<<"${VF_RP_PACE:-100 500}"
margin="${VF_RP_MARGIN:-1.3}"
rounds="${VF_RP_ROUNDS:-3}"
case "$rounds" in ''|*[!0-9]*|0) echo "recording_pacing: VF_RP_ROUNDS must be a whole number >= 1, got '$rounds'" >&2; exit 2 ;; esac

# One benchmark_ros.sh row for `n` agents, its fields separated by spaces (see its header:
# agents mode steps steps/s real-time-factor CPU% RSS start exact); the environment picks the run.
run() {
  "$here/../scripts/benchmark_ros.sh" "$1" 2>/dev/null | awk -v n="$1" '$1 == n { print; found = 1 } END { exit !found }'
}
# Field k of a row.
field() { echo "$1" | awk -v k="$2" '{ print $k }'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (a + 0 > 0 && b + 0 > 0) printf "%.2f", a / b; else print "n/a" }'; }
# The median of the rounds that gave a number (vf_median), or n/a if none did.
median() { local m; m=$(vf_median "$@"); echo "${m:-n/a}"; }

echo "load before: $(uptime | sed 's/.*load average: //')"
echo
rounds_line=()
echo "| agents | unrecorded steps/s | recorded steps/s | recorded / unrecorded (>= 0.5) | exact |"
echo "| --- | --- | --- | --- | --- |"
for n in "${record_counts[@]}"; do
  # Runs of a few seconds (benchmark_ros.sh's default lasts 0.1 s unrecorded at 100 agents on a
  # fast machine, too short for a ratio): max(1200, 1.2e6 / agents) steps unless VF_BENCH_STEPS.
  steps=${VF_BENCH_STEPS:-$(( n > 0 && 1200000 / n > 1200 ? 1200000 / n : 1200 ))}
  plains=() recordeds=() ratios=() exact=yes
  for ((round = 1; round <= rounds; ++round)); do
    plain=$(VF_BENCH_STEPS=$steps run "$n" || echo "$n - - n/a")
    recorded=$(VF_BENCH_STEPS=$steps VF_BENCH_RECORD=1 run "$n" || echo "$n - - n/a - - - - no")
    plains+=("$(field "$plain" 4)") recordeds+=("$(field "$recorded" 4)")
    ratios+=("$(ratio "$(field "$recorded" 4)" "$(field "$plain" 4)")")
    [ "$(field "$recorded" 9)" = yes ] || exact=no
  done
  rounds_line+=("- $n agents: unrecorded ${plains[*]}; recorded ${recordeds[*]}; ratios ${ratios[*]}")
  echo "| $n | $(median "${plains[@]}") | $(median "${recordeds[@]}") | $(median "${ratios[@]}") | $exact |"
done
if [ ${#record_counts[@]} -gt 0 ]; then
  echo
  echo "Recording: $rounds rounds per count (steps/s, then recorded / unrecorded per round):"
  printf '%s\n' "${rounds_line[@]}"
fi
echo
echo "| agents | h s | unpaced steps/s | unpaced real-time factor | paced steps/s | paced: simulated s | paced: wall s | paced sim / wall (>= 0.98 where unpaced >= 1.2) |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
for n in "${pace_counts[@]}"; do
  first=$(run "$n" || echo "$n - - n/a")
  rate0=$(field "$first" 4)
  h=$(awk -v r="$rate0" -v m="$margin" 'BEGIN { if (r + 0 > 0) printf "%.4g", m / r; else print "" }')
  if [ -z "$h" ]; then
    echo "| $n | n/a | n/a | n/a | n/a | n/a | n/a | n/a |"
    continue
  fi
  # VF_RP_SECONDS (default 10) of simulated time: the start and the end add a fixed 0.1 s or so.
  steps=$(awk -v h="$h" -v s="${VF_RP_SECONDS:-10}" 'BEGIN { printf "%d", s / h + 0.999 }')
  unpaced=$(VF_BENCH_STEPS=$steps VF_BENCH_MAKE_FLAGS="--time-step $h" run "$n" || echo "$n - - n/a n/a")
  paced=$(VF_BENCH_STEPS=$steps VF_BENCH_MAKE_FLAGS="--time-step $h" VF_BENCH_ARGS="rate:=1" run "$n" || echo "$n - - n/a n/a")
  steps=$(field "$paced" 3) prate=$(field "$paced" 4)
  sim=$(awk -v s="$steps" -v h="$h" 'BEGIN { printf "%.2f", s * h }')
  wall=$(awk -v s="$steps" -v r="$prate" 'BEGIN { if (r + 0 > 0) printf "%.2f", s / r; else print "n/a" }')
  # The row's real-time factor has one decimal; steps/s x h is finer (steps/s is rounded to 1).
  keeps=$(awk -v r="$prate" -v h="$h" 'BEGIN { if (r + 0 > 0) printf "%.3f", r * h; else print "n/a" }')
  urtf=$(awk -v r="$(field "$unpaced" 4)" -v h="$h" 'BEGIN { if (r + 0 > 0) printf "%.2f", r * h; else print "n/a" }')
  echo "| $n | $h | $(field "$unpaced" 4) | $urtf | $prate | $sim | $wall | $keeps |"
done
echo
echo "load after: $(uptime | sed 's/.*load average: //')"
