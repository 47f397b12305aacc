#!/usr/bin/env python3
"""Heatmap of a region-of-attraction campaign (roa.csv), in the manner of the paper's Section 6.2.

usage: plot_roa.py --roa roa.csv --scenario FILE|NAME --agent I [--time-step H] --out roa.png
Colour: time of the first converged step; grey: did not converge; black: diverged. The desired
shape (edges and agents) is drawn on top, with the moved agent's desired position circled.
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
    parser.add_argument("--roa", required=True)
    parser.add_argument("--scenario", required=True)
    parser.add_argument("--agent", type=int, required=True)
    parser.add_argument("--time-step", type=float, default=None)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    cells = data.load_csv(args.roa, data.ROA_HEADER)
    scenario = data.read_scenario(args.scenario)
    if cells.shape[0] == 0:
        fail(f"{args.roa}: no cells")
    if not 0 <= args.agent < scenario.n:
        fail(f"--agent: must be 0..{scenario.n - 1} (the scenario {scenario.name} has {scenario.n} agents)")
    ix, iy = cells[:, 0].astype(int), cells[:, 1].astype(int)
    if sorted(zip(iy, ix)) != [(j, i) for j in range(iy.max() + 1) for i in range(ix.max() + 1)]:
        fail(f"{args.roa}: the cells are not one whole grid (each ix, iy once)")
    plots.plot_region_of_attraction(args.out, cells, scenario, args.agent,
                                    args.time_step or scenario.time_step)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
