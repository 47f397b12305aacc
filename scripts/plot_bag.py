#!/usr/bin/python3
"""Plots a recorded distributed run (a bag from formation.launch record:=true) and prints the
summary: the same PNGs as plot_simulation.py, from the agents' states and the monitor's status.

usage: plot_bag.py --bag run.bag --scenario FILE [--out-dir output] [--prefix NAME]
"""
import argparse
import os
import sys

import numpy as np

# The package is importable once devel/setup.bash is sourced; this also finds it in a checkout.
sys.path.append(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src"))
from variational_formation import data, plots  # noqa: E402
from variational_formation.cli import fail  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bag", required=True)
    parser.add_argument("--scenario", required=True)
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
    try:
        with rosbag.Bag(args.bag) as bag:
            for topic, msg, _ in bag.read_messages(topics=["/formation/status"] +
                                                    [f"/formation/agent_{i}/state" for i in range(n)]):
                if topic == "/formation/status":
                    status[msg.step] = msg
                else:
                    positions[(msg.step, msg.id)] = list(msg.position) + [0.0] * (3 - len(msg.position))
    except Exception as e:  # rosbag raises several unrelated types for unreadable files
        fail(f"{args.bag}: cannot read the bag ({e})")
    steps = sorted(status)
    if not steps or steps != list(range(len(steps))):
        fail(f"{args.bag}: the status messages do not cover steps 0..N without gaps")
    missing = [(k, i) for k in steps for i in range(n) if (k, i) not in positions]
    if missing:
        fail(f"{args.bag}: {len(missing)} agent states missing, first (step, agent) = {missing[0]}")
    q = np.array([[positions[(k, i)] for i in range(n)] for k in steps])
    t = np.array([status[k].time for k in steps])
    energy = np.array([status[k].energy for k in steps])
    error = np.array([status[k].max_distance_error for k in steps])
    p = np.array([[status[k].linear_momentum.x, status[k].linear_momentum.y, status[k].linear_momentum.z] for k in steps])
    a = np.array([[status[k].angular_momentum.x, status[k].angular_momentum.y, status[k].angular_momentum.z]
                  for k in steps])
    prefix = args.prefix or scenario.name or "run"
    for path in plots.plot_all(args.out_dir, prefix, prefix + " (distributed)", t, q, dimension,
                                  energy, error, p, a, kappa, h, scenario.edges).values():
        print(f"wrote {path}")
    last = status[steps[-1]]
    print(f"converged: {'yes, from step %d' % last.converged_step if last.converged else 'no'}")
    print(plots.summary(t, energy, error, p, a, kappa, h))


if __name__ == "__main__":
    main()
