#!/usr/bin/env bash
# Lockstep throughput with the agents on other hosts: a hexagon of 3000 steps (no recording),
# its agents on two Linux network-namespace hosts (one agent.launch each) and the master and
# monitor on a third, joined by veth pairs and a bridge, against plain formation.launch with
# everything on one host (loopback). Prints the monitor's steps/s of each run and the medians.
# Needs root (ip netns), like the multi-host test it shares the hosts with
# (test/ros/multihost_test.py).
# usage: sudo ./scripts/benchmark_multihost.sh [--steps N] [--repeats R]
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
vf_install_dependencies
vf_build
vf_source
exec /usr/bin/python3 "$REPO/test/ros/multihost_test.py" --benchmark "$@"
