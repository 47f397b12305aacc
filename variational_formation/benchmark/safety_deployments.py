#!/usr/bin/python3
"""Scattered deployments with and without the safety filter (issue 31), through the built tools.

For 6 robots (a hexagon of side 1 m) and 12 robots (a 12-gon of side 1 m), both with the complete
graph: starts uniform in a 4 m x 4 m square at least 0.4 m apart (make_scenario --scatter),
r = 0.25 m, R = 1 m, gamma = 0.2, kappa = 2, h = 0.02 s, 3000 steps (60 s); with and without two
obstacles, and with the filter off for comparison. Prints one table row per case: the closest
approach of any pair over all runs, the runs in which a pair came closer than r, the closest
approach to an obstacle's edge (the filter keeps r/2), the share that reached the shape (every
pair within 1% of the desired distance, speeds below 0.1 m/s, the mirror image allowed: simulate's
verdict on its last line), the median time
to the shape, and the blocked runs.

usage: benchmark/safety_deployments.py [--runs 100] [--bin DIR]
DIR holds simulate and make_scenario (default: the workspace's devel space).
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile

import numpy as np
import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_BIN = os.path.join(HERE, "..", "..", ".ws", "devel", "lib", "variational_formation")
R_MIN = 0.25
# A disc and a box inside the deployment square (centred on the shape's centroid, the origin).
OBSTACLES = "obstacles:\n  - {center: [0.3, 0.2], radius: 0.3}\n  - {min: [-1.4, -0.9], max: [-1.1, -0.3]}\n"
DISCS = [((0.3, 0.2), 0.3)]
BOXES = [((-1.4, -0.9), (-1.1, -0.3))]


def obstacle_clearance(q):
    """Smallest distance from any agent, at any step, to an obstacle's edge [m]; q[k, i, 0:2]."""
    best = np.inf
    for centre, radius in DISCS:
        best = min(best, float((np.linalg.norm(q - np.array(centre), axis=2) - radius).min()))
    for lo, hi in BOXES:
        nearest = np.clip(q, np.array(lo), np.array(hi))
        best = min(best, float(np.linalg.norm(q - nearest, axis=2).min()))
    return best


def closest_pair(q):
    """Smallest pair distance over all steps [m]; q[k, i, 0:2]."""
    diff = q[:, :, None, :] - q[:, None, :, :]
    d = np.linalg.norm(diff, axis=3)
    n = q.shape[1]
    d[:, np.arange(n), np.arange(n)] = np.inf
    return float(d.min())


def run_case(bin_dir, tmp, agents, obstacles, safety, runs):
    rows = []
    seed = 0
    skipped = 0
    while len(rows) < runs:
        seed += 1
        path = os.path.join(tmp, f"d{agents}_{seed}.yaml")
        subprocess.run([os.path.join(bin_dir, "make_scenario"), "--shape", "ring", "--agents", str(agents),
                        "--chords", str(agents // 2 - 1), "--scatter", "4", "--min-gap", "0.4", "--seed", str(seed),
                        "--safety", "0.25", "1", "0.2", "--time-step", "0.02", "--steps", "3000", "--out", path],
                       check=True, capture_output=True)
        with open(path) as f:
            text = f.read()
        starts = np.array([a["initial_position"] for a in yaml.safe_load(text)["agents"]])
        if obstacles and obstacle_clearance(starts[None]) < R_MIN / 2:
            skipped += 1  # a start on an obstacle, which the loader refuses: the same seeds in every case
            continue
        # Interchangeable robots: the mirror image of the shape is the shape (doc/scenarios.md).
        text += "mirror: allowed\n"
        if obstacles:
            text += OBSTACLES
        if not safety:
            # Off: no filter (obstacles only measured); require_convergence makes simulate judge the shape.
            text = re.sub(r"^safety:.*\n", "require_convergence: true\n", text, flags=re.M)
            text = text.replace(OBSTACLES, "")
        with open(path, "w") as f:
            f.write(text)
        traj = path + ".csv"
        r = subprocess.run([os.path.join(bin_dir, "simulate"), "--scenario", path, "--out", traj],
                           capture_output=True, text=True)
        if r.returncode == 2:
            sys.exit(r.stderr)
        # The last line is the run's one verdict (both cases), blocked runs included.
        lines = r.stdout.splitlines()
        verdict = lines[-1]
        m = re.search(r"at step \d+ \(t = ([0-9.]+) s\)", verdict)
        data = np.loadtxt(traj, delimiter=",", skiprows=1)
        q = data[:, 3:5].reshape(-1, agents, 2)
        rows.append(dict(converged=verdict.startswith("formation: converged to the desired shape"),
                         time=float(m.group(1)) if m else None,
                         blocked=verdict.startswith("formation: not converged (blocked: "),
                         closest=closest_pair(q), clearance=obstacle_clearance(q) if obstacles else None))
        os.remove(traj)
    return rows, skipped


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=100)
    parser.add_argument("--bin", default=DEFAULT_BIN)
    args = parser.parse_args()
    print("| robots | obstacles | filter | runs | closest approach [m] | runs closer than r | closest to an "
          "obstacle [m] | reached the shape | median time to shape [s] | blocked |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory(prefix="vf_safety_") as tmp:
        for agents in (6, 12):
            for obstacles in (False, True):
                for safety in (True, False):
                    rows, skipped = run_case(args.bin, tmp, agents, obstacles, safety, args.runs)
                    times = [r["time"] for r in rows if r["converged"]]
                    clearance = min(r["clearance"] for r in rows) if obstacles else None
                    print(f"| {agents} | {'2' if obstacles else '-'}{f' ({skipped} starts refused)' if skipped else ''}"
                          f" | {'on' if safety else 'off'} | {len(rows)} | {min(r['closest'] for r in rows):.3f}"
                          f" | {sum(r['closest'] < R_MIN for r in rows)}"
                          f" | {'-' if clearance is None else f'{clearance:.3f}'}"
                          f" | {sum(r['converged'] for r in rows)}/{len(rows)}"
                          f" | {statistics.median(times) if times else float('nan'):.2f}"
                          f" | {sum(r['blocked'] for r in rows)} |", flush=True)


if __name__ == "__main__":
    main()
