#!/usr/bin/env python3
"""The paper's Euler comparison (Section 6.1): the square scenario with the variational
integrator and with explicit Euler at h = 0.05, 0.008 and 0.005, over the same simulated time.

usage: euler_comparison.py [--scenario FILE|NAME (square)] [--duration 15] [--out-dir output]
                           [--simulate PATH]
Prints, per method and h: bounded or not, the final formation error, and the time at which
the energy fell below 1e-6 of its initial value; writes euler_comparison.png (trajectories and
energy side by side; 3D scenarios are drawn in 3D). The simulate binary is looked up in
$VF_WS (default .ws in the repository), beside this script (an install space), then on PATH,
unless --simulate is given. Installed, the defaults are the package's square and ./output.
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

# The package is importable once devel/setup.bash is sourced; this also finds it in a checkout.
sys.path.append(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src"))
from variational_formation import data, plots  # noqa: E402
from variational_formation.cli import description, fail  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
# A checkout has package.xml at REPO; an install space keeps this script in
# <prefix>/lib/variational_formation and the package's files in <prefix>/share/variational_formation.
CHECKOUT = os.path.isfile(os.path.join(REPO, "package.xml"))
SHARE = REPO if CHECKOUT else os.path.join(HERE, "..", "..", "share", "variational_formation")
STEPS_H = (0.05, 0.008, 0.005)
METHODS = (("vi", "variational"), ("euler", "explicit Euler"))


def find_simulate(given):
    if given:
        if not (os.path.isfile(given) and os.access(given, os.X_OK)):
            fail(f"--simulate: '{given}' is not an executable file")
        return given
    workspace = os.environ.get("VF_WS") or os.path.join(os.path.dirname(REPO), ".ws")
    for candidate in (os.path.join(workspace, "devel/lib/variational_formation/simulate"),
                      os.path.join(HERE, "simulate"), shutil.which("simulate")):
        if candidate and os.access(candidate, os.X_OK):
            return candidate
    fail(f"no simulate binary in {workspace} or on PATH; build first (./scripts/test.sh) or pass --simulate")


def run(simulate, scenario, method, h, steps, tmp):
    """One simulate run: q[k, i, 0:3] and the metrics."""
    traj, metrics = os.path.join(tmp, "t.csv"), os.path.join(tmp, "m.csv")
    result = subprocess.run([simulate, "--scenario", scenario, "--out", traj, "--metrics", metrics,
                             "--method", method, "--time-step", repr(h), "--steps", str(steps)],
                            capture_output=True, text=True)
    if result.returncode != 0:
        fail(result.stderr.strip().splitlines()[-1] if result.stderr.strip() else "simulate failed")
    return data.read_trajectory(traj), data.read_metrics(metrics)


def main():
    parser = argparse.ArgumentParser(description=description(__doc__))
    parser.add_argument("--scenario", default=os.path.normpath(os.path.join(SHARE, "config", "square.yaml")))
    parser.add_argument("--duration", type=float, default=15.0)
    parser.add_argument("--out-dir", default=os.path.join(REPO, "output") if CHECKOUT else "output")
    parser.add_argument("--simulate", default=None)
    args = parser.parse_args()
    if not args.duration > 0:
        fail("--duration: must be > 0")
    simulate = find_simulate(args.simulate)
    args.scenario = data.scenario_path(args.scenario)
    scenario = data.read_scenario(args.scenario)
    runs, rows = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for method, label in METHODS:
            for h in STEPS_H:
                q, m = run(simulate, args.scenario, method, h, int(round(args.duration / h)), tmp)
                bounded = bool(np.all(np.isfinite(q)) and np.abs(q).max() < 1e6)
                below = np.nonzero(m.energy < 1e-6 * m.energy[0])[0]
                t_small = f"{m.t[below[0]]:.3f} s" if bounded and below.size else "never"
                final_error = f"{m.error[-1]:.3e}" if bounded else "n/a"
                rows.append((label, h, "bounded" if bounded else "DIVERGED", final_error, t_small))
                runs.append((label, h, q, m.t, m.energy, bounded))
    os.makedirs(args.out_dir, exist_ok=True)
    path = os.path.join(args.out_dir, "euler_comparison.png")
    plots.plot_method_comparison(path, f"{scenario.name}: variational integrator vs explicit Euler",
                                 runs, scenario.dimension)
    print(f"{'method':16} {'h':>6}  {'run':9} {'final error [m]':>15}  E < 1e-6 E_0 at")
    for label, h, state, err, when in rows:
        print(f"{label:16} {h:6}  {state:9} {err:>15}  {when}")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
