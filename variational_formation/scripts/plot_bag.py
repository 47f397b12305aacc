#!/usr/bin/python3
"""Plots a recorded distributed run (a bag of formation.launch record:=true) and prints the
summary: the same PNGs as plot_simulation.py, from the agents' states and the monitor's status.

Every part of a split recording is read (name.bag, name_1.bag, ...). The formation's namespace
is the one of the bag's status topic (or --ns). The scenario is a file or a name in the
package's config/; one of another formation (agent count, dimension) is refused.

usage: plot_bag.py --bag run.bag --scenario FILE|NAME [--ns /team_a/formation] [--out-dir output] [--prefix NAME]
"""
import argparse
import os
import sys

import numpy as np

# The package is importable once devel/setup.bash is sourced; this also finds it in a checkout.
sys.path.append(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src"))
from variational_formation import data, plots  # noqa: E402
from variational_formation.cli import description, fail  # noqa: E402

STATUS_TYPE = "variational_formation_msgs/FormationStatus"


def formation_namespace(topics, given):
    """The namespace of the formation in a bag's {topic: type}: `given`, or the one status topic's."""
    if given:
        ns = "/" + given.strip("/")
        if topics.get(ns + "/status") != STATUS_TYPE:
            fail(f"--ns: no {ns}/status in the bag")
        return ns
    found = sorted(t[:-len("/status")] for t, kind in topics.items() if kind == STATUS_TYPE and t.endswith("/status"))
    if not found:
        fail("the bag holds no formation status (record with formation.launch record:=true)")
    if len(found) > 1:
        fail(f"the bag holds several formations ({', '.join(found)}): choose one with --ns")
    return found[0]


def main():
    parser = argparse.ArgumentParser(description=description(__doc__))
    parser.add_argument("--bag", required=True, help="the bag, or its first part")
    parser.add_argument("--scenario", required=True, help="a scenario file or a name in config/")
    parser.add_argument("--ns", default=None, help="the formation's namespace (default: the bag's)")
    parser.add_argument("--out-dir", default="output")
    parser.add_argument("--prefix", default=None)
    args = parser.parse_args()
    try:
        import rosbag
    except ImportError:
        fail("python3-rosbag is not installed (run with /usr/bin/python3)")
    scenario = data.read_scenario(args.scenario)
    n, dimension, kappa, h = scenario.n, scenario.dimension, scenario.kappa, scenario.time_step
    positions, status = {}, {}
    parts = data.bag_parts(args.bag)
    try:
        bags = [rosbag.Bag(part) for part in parts]
        topics = {t: info.msg_type for bag in bags for t, info in bag.get_type_and_topic_info().topics.items()}
        ns = formation_namespace(topics, args.ns)
        agents = sorted(t for t in topics if t.startswith(ns + "/agent_") and t.endswith("/state"))
        if len(agents) != n:
            fail(f"{args.bag}: {ns} holds the states of {len(agents)} agents, the scenario {scenario.name} has {n}: "
                 "they do not belong together")
        for bag in bags:
            for topic, msg, _ in bag.read_messages(topics=[ns + "/status"] + agents):
                if topic == ns + "/status":
                    status[msg.step] = msg
                else:
                    if len(msg.position) != dimension or msg.id >= n:
                        fail(f"{args.bag}: agent {msg.id} has {len(msg.position)} coordinates, the scenario "
                             f"{scenario.name} is {dimension}D with {n} agents: they do not belong together")
                    positions[(msg.step, msg.id)] = list(msg.position) + [0.0] * (3 - len(msg.position))
        for bag in bags:
            bag.close()
    except SystemExit:
        raise
    except Exception as e:  # rosbag raises several unrelated types for unreadable files
        fail(f"{args.bag}: cannot read the bag ({e})")
    steps = sorted(status)
    if not steps or steps != list(range(len(steps))):
        fail(f"{args.bag}: the status messages of {ns} do not cover steps 0..N without gaps")
    missing = [(k, i) for k in steps for i in range(n) if (k, i) not in positions]
    if missing:
        fail(f"{args.bag}: {len(missing)} agent states missing, first (step, agent) = {missing[0]}")
    print(f"read {len(parts)} bag file{'s' if len(parts) > 1 else ''} ({', '.join(parts)}), formation {ns}")
    q = np.array([[positions[(k, i)] for i in range(n)] for k in steps])
    t = np.array([status[k].time for k in steps])
    energy = np.array([status[k].energy for k in steps])
    error = np.array([status[k].max_distance_error for k in steps])
    p = np.array([[status[k].linear_momentum.x, status[k].linear_momentum.y, status[k].linear_momentum.z] for k in steps])
    a = np.array([[status[k].angular_momentum.x, status[k].angular_momentum.y, status[k].angular_momentum.z]
                  for k in steps])
    prefix = args.prefix or scenario.name or "run"
    paths = plots.plot_all(args.out_dir, prefix, prefix + " (distributed)", t, q, dimension,
                           energy, error, p, a, kappa, h, scenario.edges)
    separation = np.array([status[k].min_separation for k in steps])  # NaN without a safety block
    plots.add_separation(paths, args.out_dir, prefix, prefix + " (distributed)", t, separation,
                         scenario.safety_radius)
    for path in paths.values():
        print(f"wrote {path}")
    last = status[steps[-1]]
    print(f"converged: {'yes, from step %d' % last.converged_step if last.converged else 'no'}")
    print(plots.summary(t, energy, error, p, a, kappa, h))


if __name__ == "__main__":
    main()
