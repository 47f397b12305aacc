#!/usr/bin/python3
"""Whether a recorded lockstep run is exact: every agent's state at every step is in the bag once
and its position equals `simulate`'s, bit for bit (both print doubles that round-trip).

  bag_vs_simulate.py SCENARIO.yaml BAG [--ns /formation]

Prints one line, "exact: N states" or what differs, and exits 0 only if exact. Used by
scripts/benchmark_ros.sh with VF_BENCH_RECORD=1.
"""
import argparse
import os
import sys

import rosbag

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "test", "ros"))
import vf_rostest  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scenario")
    parser.add_argument("bag")
    parser.add_argument("--ns", default="/formation")
    args = parser.parse_args()
    for path in (args.scenario, args.bag):
        if not os.path.isfile(path):
            print(f"bag_vs_simulate: no such file: {path}", file=sys.stderr)
            return 2
    scenario = vf_rostest.load_scenario(args.scenario)
    n, steps = scenario["n"], int(scenario["steps"])
    expected = vf_rostest.simulate(args.scenario)
    seen, differ, twice = set(), 0, 0
    prefix = args.ns + "/agent_"
    for part in vf_rostest.bag_parts(args.bag):
        with rosbag.Bag(part) as bag:
            for _, msg, _ in bag.read_messages(
                    connection_filter=lambda topic, *_: topic.startswith(prefix) and topic.endswith("/state")):
                key = (msg.id, msg.step)
                twice += key in seen
                seen.add(key)
                differ += list(msg.position) != expected.get(key)
    missing = n * (steps + 1) - len(seen)
    if differ or twice or missing:
        print(f"not exact: {differ} positions differ from simulate, {missing} states missing, {twice} twice")
        return 1
    print(f"exact: {len(seen)} states ({n} agents x {steps + 1} steps) equal simulate bit for bit")
    return 0


if __name__ == "__main__":
    sys.exit(main())
