#!/usr/bin/env python3
"""Heatmap of a delay x loss campaign (<name>_delay_margin.csv written by `delay_margin`).

usage: plot_delay_margin.py --summary DIR/<name>_delay_margin.csv --out delay_margin.png
Colour: fraction of runs congruent at the end, per delay D (steps) and loss probability P; the
number in each cell is the median time to congruence [s]. The predicted margin D* (linearised
delayed recurrence) is marked by a dashed line between D* and D* + 1.
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

# The package is importable once devel/setup.bash is sourced; this also finds it in a checkout.
sys.path.append(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src"))
from variational_formation import data  # noqa: E402
from variational_formation.cli import fail  # noqa: E402

HEADER = ("delay_steps,loss,runs,congruent_fraction,median_congruent_step,median_congruent_time,"
          "lost_fraction,predicted_margin,predicted_capped,unstable_roots")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--summary", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--title", default=None)
    args = parser.parse_args()
    rows = data.load_csv(args.summary, HEADER)
    if rows.shape[0] == 0:
        fail(f"{args.summary}: no rows")
    delays = sorted({int(r[0]) for r in rows})
    losses = sorted({float(r[1]) for r in rows})
    fraction = np.full((len(losses), len(delays)), np.nan)
    median_time = np.full_like(fraction, np.nan)
    for r in rows:
        i, j = losses.index(float(r[1])), delays.index(int(r[0]))
        fraction[i, j] = float(r[3])
        median_time[i, j] = float(r[5])
    margin, capped = int(float(rows[0][7])), int(float(rows[0][8]))

    fig, ax = plt.subplots(figsize=(1.0 + 0.45 * len(delays), 1.6 + 0.45 * len(losses)))
    image = ax.imshow(fraction, origin="lower", aspect="auto", cmap="viridis", vmin=0, vmax=1,
                      extent=(delays[0] - 0.5, delays[-1] + 0.5, -0.5, len(losses) - 0.5))
    for i in range(len(losses)):
        for j, d in enumerate(delays):
            if median_time[i, j] >= 0:
                ax.text(d, i, "%.1f" % median_time[i, j], ha="center", va="center", fontsize=6,
                        color="white" if fraction[i, j] < 0.6 else "black")
    if margin >= 0:
        label = "predicted D* = %d%s" % (margin, " (or more)" if capped else "")
        ax.axvline(margin + 0.5, color="red", linestyle="--", linewidth=1.5, label=label)
        ax.legend(loc="upper right", fontsize=7)
    ax.set_yticks(range(len(losses)))
    ax.set_yticklabels(["%g" % p for p in losses])
    ax.set_xticks(delays)
    ax.set_xlabel("delay D [steps]")
    ax.set_ylabel("loss probability P")
    ax.set_title(args.title or os.path.basename(args.summary).replace("_delay_margin.csv", ""),
                 fontsize=9)
    fig.colorbar(image, ax=ax, label="fraction congruent")
    fig.tight_layout()
    try:
        fig.savefig(args.out, dpi=110)
    except OSError as e:
        fail(f"--out: cannot write {args.out}: {e.strerror}")
    print("plot_delay_margin: wrote %s" % args.out)


if __name__ == "__main__":
    main()
