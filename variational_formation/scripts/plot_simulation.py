#!/usr/bin/env python3
"""Turns simulate's traj.csv and metrics.csv into PNGs and prints a summary. The scenario is a
file or a name in the package's config/; files of another formation (agent count, dimension,
step count) are refused.

usage: plot_simulation.py --scenario FILE|NAME --traj traj.csv --metrics metrics.csv
                          [--out-dir output] [--prefix NAME] [--commands FILE.csv]
With a manoeuvre (the scenario's, or --commands as given to simulate) it also draws
<prefix>_manoeuvre.png: the centroid's path against the commanded one, and the shape at a few instants.
With a safety block it also draws <prefix>_separation.png: the closest pair over time against r.
"""
import argparse
import os
import sys

# The package is importable once devel/setup.bash is sourced; this also finds it in a checkout.
sys.path.append(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src"))
from variational_formation import data, plots  # noqa: E402
from variational_formation.cli import description, fail  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=description(__doc__))
    parser.add_argument("--scenario", required=True)
    parser.add_argument("--traj", required=True)
    parser.add_argument("--metrics", required=True)
    parser.add_argument("--out-dir", default="output")
    parser.add_argument("--prefix", default=None)
    parser.add_argument("--commands", default=None)
    args = parser.parse_args()
    args.scenario = data.scenario_path(args.scenario)
    scenario = data.read_scenario(args.scenario)
    q = data.read_trajectory(args.traj, scenario.n, scenario.dimension, f"the scenario {scenario.name}")
    m = data.read_metrics(args.metrics)
    if len(m.t) != q.shape[0]:
        fail(f"{args.metrics}: {len(m.t)} steps, {args.traj}: {q.shape[0]}: they do not belong together")
    h = m.t[1] - m.t[0] if len(m.t) > 1 else 1.0
    prefix = args.prefix or scenario.name or "run"
    paths = plots.plot_all(args.out_dir, prefix, prefix, m.t, q, scenario.dimension, m.energy, m.error,
                           m.p, m.a, scenario.kappa, h, scenario.edges)
    plots.add_separation(paths, args.out_dir, prefix, prefix, m.t, m.min_separation, scenario.safety_radius)
    commanded = data.commanded_velocities(args.scenario, len(m.t) - 1, h, args.commands)
    if commanded is not None:
        paths["manoeuvre"] = os.path.join(args.out_dir, f"{prefix}_manoeuvre.png")
        plots.plot_manoeuvre(paths["manoeuvre"], prefix, m.t, q, scenario.edges, commanded)
    for p in paths.values():
        print(f"wrote {p}")
    print(plots.summary(m.t, m.energy, m.error, m.p, m.a, scenario.kappa, h))


if __name__ == "__main__":
    main()
