#!/usr/bin/env python3
"""The paper's Euler comparison (Section 6.1): the square scenario with the variational
integrator and with explicit Euler at h = 0.05, 0.008 and 0.005, over the same simulated time.

usage: euler_comparison.py [--scenario config/square.yaml] [--duration 15] [--out-dir output]
                           [--simulate PATH]
Prints, per method and h: bounded or not, the final formation error, and the time at which
the energy fell below 1e-6 of its initial value; writes euler_comparison.png (trajectories and
energy side by side).
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STEPS_H = (0.05, 0.008, 0.005)
METHODS = (("vi", "variational"), ("euler", "explicit Euler"))


def fail(message):
    print(f"euler_comparison: error: {message}", file=sys.stderr)
    sys.exit(2)


def find_simulate(given):
    if given:
        if not (os.path.isfile(given) and os.access(given, os.X_OK)):
            fail(f"--simulate: '{given}' is not an executable file")
        return given
    for candidate in (os.path.join(REPO, ".ws/devel/lib/variational_formation/simulate"),
                      shutil.which("simulate")):
        if candidate and os.access(candidate, os.X_OK):
            return candidate
    fail("no simulate binary found; build first (./scripts/test.sh) or pass --simulate")


def run(simulate, scenario, method, h, steps, tmp):
    traj, metrics = os.path.join(tmp, "t.csv"), os.path.join(tmp, "m.csv")
    result = subprocess.run([simulate, "--scenario", scenario, "--out", traj, "--metrics", metrics,
                             "--method", method, "--time-step", repr(h), "--steps", str(steps)],
                            capture_output=True, text=True)
    if result.returncode != 0:
        fail(result.stderr.strip().splitlines()[-1] if result.stderr.strip() else "simulate failed")
    t = np.loadtxt(traj, delimiter=",", skiprows=1, ndmin=2)
    m = np.loadtxt(metrics, delimiter=",", skiprows=1, ndmin=2)
    n = int(t[:, 2].max()) + 1
    q = t[:, 3:5].reshape(-1, n, 2)
    return q, m


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default=os.path.join(REPO, "config/square.yaml"))
    parser.add_argument("--duration", type=float, default=15.0)
    parser.add_argument("--out-dir", default=os.path.join(REPO, "output"))
    parser.add_argument("--simulate", default=None)
    args = parser.parse_args()
    if not args.duration > 0:
        fail("--duration: must be > 0")
    simulate = find_simulate(args.simulate)
    os.makedirs(args.out_dir, exist_ok=True)
    fig, axes = plt.subplots(len(METHODS), len(STEPS_H) + 1, figsize=(16, 7.5))
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for r, (method, label) in enumerate(METHODS):
            for c, h in enumerate(STEPS_H):
                steps = int(round(args.duration / h))
                q, m = run(simulate, args.scenario, method, h, steps, tmp)
                t, energy, error = m[:, 1], m[:, 2], m[:, 3]
                bounded = bool(np.all(np.isfinite(q)) and np.abs(q).max() < 1e6)
                below = np.nonzero(energy < 1e-6 * energy[0])[0]
                t_small = f"{t[below[0]]:.3f} s" if bounded and below.size else "never"
                final_error = f"{error[-1]:.3e}" if bounded else "n/a"
                rows.append((label, h, "bounded" if bounded else "DIVERGED", final_error, t_small))
                ax = axes[r, c]
                for i in range(q.shape[1]):
                    ok = np.all(np.isfinite(q[:, i]), axis=1) & (np.abs(q[:, i]).max(axis=1) < 1e3)
                    line, = ax.plot(q[ok, i, 0], q[ok, i, 1], lw=1)
                    ax.plot(q[0, i, 0], q[0, i, 1], "x", color=line.get_color())
                ax.set_title(f"{label}, h = {h}" + ("" if bounded else " (diverged)"), fontsize=9)
                ax.set_aspect("equal", adjustable="datalim")
                good = np.isfinite(energy) & (energy > 0)
                axes[r, -1].semilogy(t[good], energy[good] / energy[0], label=f"h = {h}")
            axes[r, -1].set_title(f"{label}: E / E_0", fontsize=9)
            axes[r, -1].set_xlabel("t [s]")
            axes[r, -1].set_ylim(1e-12, 1e3)
            axes[r, -1].legend(fontsize="small")
            axes[r, -1].grid(True, which="both", alpha=0.3)
    fig.suptitle("Square: variational integrator vs explicit Euler (x = start)")
    fig.tight_layout()
    path = os.path.join(args.out_dir, "euler_comparison.png")
    fig.savefig(path, dpi=100)
    print(f"{'method':16} {'h':>6}  {'run':9} {'final error [m]':>15}  E < 1e-6 E_0 at")
    for label, h, state, err, when in rows:
        print(f"{label:16} {h:6}  {state:9} {err:>15}  {when}")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
