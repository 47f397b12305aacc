#!/usr/bin/env python3
"""Turns simulate's traj.csv and metrics.csv into PNGs and prints a summary.

usage: plot_simulation.py --scenario FILE --traj traj.csv --metrics metrics.csv
                          [--out-dir output] [--prefix NAME]
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_plots  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", required=True)
    parser.add_argument("--traj", required=True)
    parser.add_argument("--metrics", required=True)
    parser.add_argument("--out-dir", default="output")
    parser.add_argument("--prefix", default=None)
    args = parser.parse_args()
    scenario = vf_plots.read_scenario(args.scenario)
    n, dimension, kappa, edges = scenario.n, scenario.dimension, scenario.kappa, scenario.edges
    traj = vf_plots.load_csv(args.traj, "step,t,agent,x,y,z")
    metrics = vf_plots.load_csv(args.metrics, "step,t,energy,max_distance_error,px,py,pz,ax,ay,az")
    if traj.shape[0] % n != 0 or traj.shape[0] == 0:
        vf_plots.fail(f"{args.traj}: {traj.shape[0]} rows is not a multiple of {n} agents")
    steps = traj.shape[0] // n
    q = traj[:, 3:6].reshape(steps, n, 3)
    t = metrics[:, 1]
    h = t[1] - t[0] if len(t) > 1 else 1.0
    prefix = args.prefix or scenario.name or "run"
    paths = vf_plots.plot_all(args.out_dir, prefix, prefix, t, q, dimension, metrics[:, 2],
                              metrics[:, 3], metrics[:, 4:7], metrics[:, 7:10], kappa, h, edges)
    for p in paths.values():
        print(f"wrote {p}")
    print(vf_plots.summary(t, metrics[:, 2], metrics[:, 3], metrics[:, 4:7], metrics[:, 7:10],
                           kappa, h))


if __name__ == "__main__":
    main()
