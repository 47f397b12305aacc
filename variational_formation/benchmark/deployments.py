#!/usr/bin/python3
"""Scattered deployments of the hexagon (issue 32): how often the formation folds, with the
shipped 9-edge graph and with a globally rigid one from `make_scenario --graph`, and what slot
assignment (`assignment: auto`) does to the paths.

  deployments.py [--runs 40] [--graph complete --graph knn ...] [--bin DIR] [--keep DIR]

Each deployment: 6 robots, a regular hexagon of side 1 (the shipped hexagon's shape and
numbering, scaled by 1/3), starts uniform in a 4 m x 4 m square at least 0.4 m apart (seeded:
deployment k uses numpy's default_rng(k)), kappa = 2, h = 0.02, 1500 steps, `mirror: allowed`
(robots are interchangeable here; a mirror image is counted separately). Four variants per
deployment: {shipped graph, --graph} x {assignment: none, auto}. From simulate's final line and
its trajectory: the verdict, the time to the shape, the total path length and the closest
approach of two agents. Folds are also checked independently of simulate from the final
positions (every edge within 1 %, some pair not). Prints a Markdown table.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

import numpy as np
import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


def tool(bin_dir, name):
    path = os.path.join(bin_dir, name)
    if not os.access(path, os.X_OK):
        sys.exit(f"deployments: no {name} in {bin_dir} (build it, or pass --bin)")
    return path


def starts(seed, n=6, side=4.0, gap=0.4):
    rng = np.random.default_rng(seed)
    while True:
        q = rng.uniform(0.0, side, size=(n, 2))
        d = np.linalg.norm(q[:, None] - q[None], axis=2) + np.eye(n) * 1e9
        if d.min() >= gap:
            return q


def scenario_text(name, desired, edges, q0, assignment):
    agents = "\n".join(f"  - {{id: {i}, initial_position: [{q0[i][0]!r}, {q0[i][1]!r}], "
                       f"desired_position: [{desired[i][0]!r}, {desired[i][1]!r}]}}" for i in range(len(q0)))
    return (f"name: {name}\ndimension: 2\nkappa: 2\ntime_step: 0.02\nsteps: 1500\nmirror: allowed\n"
            f"assignment: {assignment}\nagents:\n{agents}\nedges: {[list(e) for e in edges]}\n")


def run(simulate, path, traj):
    r = subprocess.run([simulate, "--scenario", path, "--out", traj], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"deployments: simulate failed on {path}: {r.stderr.strip()}")
    line = r.stdout.strip().splitlines()[-1]
    rows = np.loadtxt(traj, delimiter=",", skiprows=1)
    q = rows[:, 3:5].reshape(-1, 6, 2)
    return line, q


def independent_fold(q, desired, edges, tol=0.01):
    """Every edge within tol (relative) and some pair not, from positions alone."""
    def dist(x, i, j):
        return np.linalg.norm(x[i] - x[j])
    edges_ok = all(abs(dist(q, i, j) - dist(desired, i, j)) <= tol * dist(desired, i, j) for i, j in edges)
    pairs_ok = all(abs(dist(q, i, j) - dist(desired, i, j)) <= tol * dist(desired, i, j)
                   for i in range(6) for j in range(i + 1, 6))
    return edges_ok and not pairs_ok


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=40)
    parser.add_argument("--graph", action="append", help="make_scenario --graph value, repeatable (default: complete and knn)")
    parser.add_argument("--bin", default=os.path.join(os.path.dirname(REPO), ".ws", "devel", "lib", "variational_formation"))
    parser.add_argument("--keep", help="keep the scenarios and trajectories in this folder")
    args = parser.parse_args()
    simulate, make_scenario = tool(args.bin, "simulate"), tool(args.bin, "make_scenario")
    work = args.keep or tempfile.mkdtemp(prefix="vf_deploy_")
    os.makedirs(work, exist_ok=True)

    with open(os.path.join(REPO, "config", "hexagon.yaml")) as f:
        shipped = yaml.safe_load(f)
    desired = np.array([a["desired_position"] for a in shipped["agents"]]) / 3.0  # side 1
    graphs = {"shipped (9 edges)": [tuple(e) for e in shipped["edges"]]}
    for spec in args.graph or ["complete", "knn"]:
        out = os.path.join(work, f"rigid_{spec.replace(':', '_')}.yaml")
        subprocess.run([make_scenario, "--shape", "ring", "--agents", "6", "--graph", spec, "--out", out], check=True)
        with open(out) as f:
            rigid = yaml.safe_load(f)
        ring = np.array([a["desired_position"] for a in rigid["agents"]])
        assert np.allclose(ring, desired, atol=1e-12), "make_scenario's ring is not the hexagon's numbering"
        graphs[f"--graph {spec} ({len(rigid['edges'])} edges)"] = [tuple(e) for e in rigid["edges"]]

    results = {}
    for gname, edges in graphs.items():
        for assignment in ("none", "auto"):
            rows = []
            for k in range(1, args.runs + 1):
                q0 = starts(k)
                path = os.path.join(work, f"d{k}_{len(edges)}_{assignment}.yaml")
                with open(path, "w") as f:
                    f.write(scenario_text(f"deploy{k}", desired, edges, q0, assignment))
                line, q = run(simulate, path, os.path.join(work, "traj.csv"))
                path_length = np.linalg.norm(np.diff(q, axis=0), axis=2).sum()
                gaps = np.linalg.norm(q[:, :, None] - q[:, None], axis=3) + np.eye(6) * 1e9
                m = re.search(r"desired shape at step (\d+)", line)
                rows.append(dict(line=line, length=path_length, closest=gaps.min(),
                                 time=int(m.group(1)) * 0.02 if m else None,
                                 desired="converged to the desired shape" in line,
                                 mirror="mirror image" in line,
                                 folded="not converged: folded" in line,
                                 folded_independent=independent_fold(q[-1], desired, edges) if assignment == "none" else None))
            results[(gname, assignment)] = rows

    print(f"{args.runs} deployments, 6 agents, hexagon side 1, starts uniform in 4 m x 4 m (>= 0.4 m apart), "
          "kappa 2, h 0.02, 1500 steps\n")
    print("| graph | assignment | desired shape | of which mirror | folded (edges right) | not converged | "
          "median time to shape [s] | mean total path [m] | median closest approach [m] | runs with approach < 0.2 m |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for (gname, assignment), rows in results.items():
        times = [r["time"] for r in rows if r["time"] is not None]
        print(f"| {gname} | {assignment} | {sum(r['desired'] for r in rows)} | {sum(r['mirror'] for r in rows)} | "
              f"{sum(r['folded'] for r in rows)} | {sum(not r['desired'] and not r['folded'] for r in rows)} | "
              f"{np.median(times) if times else float('nan'):.2f} | {np.mean([r['length'] for r in rows]):.2f} | "
              f"{np.median([r['closest'] for r in rows]):.3f} | {sum(r['closest'] < 0.2 for r in rows)} |")
    # Every fold found from the positions alone must be one simulate reported, and back.
    for (gname, assignment), rows in results.items():
        if assignment == "none":
            mismatch = [i + 1 for i, r in enumerate(rows) if r["folded"] != r["folded_independent"]]
            print(f"\n{gname}: folds found from the final positions alone: "
                  f"{sum(r['folded_independent'] for r in rows)}; reported differently by simulate: {mismatch or 'none'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
