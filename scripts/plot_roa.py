#!/usr/bin/env python3
"""Heatmap of a region-of-attraction campaign (roa.csv), in the manner of the paper's Section 6.2.

usage: plot_roa.py --roa roa.csv --scenario FILE --agent I [--time-step H] --out roa.png
Colour: time of the first converged step; grey: did not converge; black: diverged. The desired
shape (edges and agents) is drawn on top, with the moved agent's desired position circled.
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_plots  # noqa: E402

HEADER = "ix,iy,x,y,converged,converged_step,diverged"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--roa", required=True)
    parser.add_argument("--scenario", required=True)
    parser.add_argument("--agent", type=int, required=True)
    parser.add_argument("--time-step", type=float, default=None)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    data = vf_plots.load_csv(args.roa, HEADER)
    scenario = vf_plots.read_scenario(args.scenario)
    desired, edges = scenario.desired, scenario.edges
    h = args.time_step or scenario.time_step
    if data.shape[0] == 0:
        vf_plots.fail(f"{args.roa}: no cells")
    if not 0 <= args.agent < len(desired):
        vf_plots.fail(f"--agent: must be 0..{len(desired) - 1}")
    ix, iy = data[:, 0].astype(int), data[:, 1].astype(int)
    nx, ny = ix.max() + 1, iy.max() + 1
    time = np.full((ny, nx), np.nan)
    status = np.zeros((ny, nx))  # 0 converged, 1 not converged, 2 diverged
    conv = data[:, 4] == 1
    time[iy[conv], ix[conv]] = data[conv, 5] * h
    status[iy[~conv], ix[~conv]] = 1
    status[iy[data[:, 6] == 1], ix[data[:, 6] == 1]] = 2
    x, y = data[:, 2], data[:, 3]
    dx = (x.max() - x.min()) / max(nx - 1, 1) or 1.0
    dy = (y.max() - y.min()) / max(ny - 1, 1) or 1.0
    extent = [x.min() - dx / 2, x.max() + dx / 2, y.min() - dy / 2, y.max() + dy / 2]

    fig, ax = plt.subplots(figsize=(7, 6))
    background = np.where(status == 0, np.nan, status)
    ax.imshow(background, origin="lower", extent=extent, cmap=ListedColormap(["0.8", "black"]),
              vmin=1, vmax=2, interpolation="nearest", aspect="equal")
    image = ax.imshow(time, origin="lower", extent=extent, cmap="viridis", interpolation="nearest",
                      aspect="equal")
    fig.colorbar(image, ax=ax, label="convergence time [s]")
    for i, j in edges:
        ax.plot(desired[[i, j], 0], desired[[i, j], 1], color="white", lw=1.5)
        ax.plot(desired[[i, j], 0], desired[[i, j], 1], color="red", lw=0.8)
    ax.plot(desired[:, 0], desired[:, 1], "o", color="red", ms=5)
    ax.plot(*desired[args.agent, :2], "o", mfc="none", mec="white", ms=12, mew=2)
    ax.set_xlim(extent[0], extent[1])
    ax.set_ylim(extent[2], extent[3])
    ax.set_xlabel("x of agent %d at start [m]" % args.agent)
    ax.set_ylabel("y of agent %d at start [m]" % args.agent)
    n = len(data)
    ax.set_title(f"{scenario.name}: region of attraction of agent {args.agent}\n"
                 f"{n} cells: {100 * conv.mean():.1f}% converged (colour), "
                 f"{100 * (status == 1).mean():.1f}% not (grey), "
                 f"{100 * (status == 2).mean():.1f}% diverged (black)", fontsize=9)
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
