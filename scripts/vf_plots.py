"""Plots of a formation run, shared by the CSV (plot_simulation.py) and bag front-ends.

Every function takes plain numpy arrays:
  t[k]            time of step k [s]
  q[k, i, a]      position of agent i at step k (a = x, y, z)
  energy[k]       discrete energy
  error[k]        largest edge distance error [m]
  p[k, 3], a[k, 3] total linear and angular momentum
"""
import os
import sys
import types

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import yaml  # noqa: E402


def fail(message):
    """One line on stderr, named after the running script, and exit status 2."""
    program = os.path.splitext(os.path.basename(sys.argv[0]))[0]
    print(f"{program}: error: {' '.join(str(message).split())}", file=sys.stderr)
    sys.exit(2)


def load_csv(path, header):
    """The rows of a CSV file whose first line must be `header`, as a 2D array; fail() if not."""
    try:
        with open(path) as f:
            first = f.readline().strip()
        if first != header:
            fail(f"{path}: expected header '{header}', got '{first}'")
        return np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    except (OSError, ValueError) as e:
        fail(f"{path}: {e}")


def read_scenario(path):
    """The fields of a scenario file (already checked by the package's loader) that the plots
    use: name, dimension, kappa, time_step, n, desired (n x d array) and edges."""
    try:
        with open(path) as f:
            s = yaml.safe_load(f)
        agents = s["agents"]
        return types.SimpleNamespace(
            name=str(s.get("name", "")), dimension=int(s["dimension"]), kappa=float(s["kappa"]),
            time_step=float(s["time_step"]), n=len(agents),
            desired=np.array([a["desired_position"] for a in agents], float),
            edges=[tuple(e) for e in s.get("edges") or []])
    except (OSError, yaml.YAMLError, KeyError, TypeError, ValueError, AttributeError) as e:
        fail(f"{path}: cannot read the scenario ({e})")


def noether_prediction(initial, kappa, h, steps):
    """e^{-kappa t_k} X_0, formed as (e^{-kappa h})^k (DESIGN.md §1: never e^{kappa t})."""
    return np.power(np.exp(-kappa * h), steps)[:, None] * initial[None, :]


def plot_trajectories(path, title, q, dimension, desired=None, edges=()):
    fig = plt.figure(figsize=(6.4, 5.6))
    if dimension == 3:
        ax = fig.add_subplot(projection="3d")
        for i in range(q.shape[1]):
            line, = ax.plot(q[:, i, 0], q[:, i, 1], q[:, i, 2], label=f"agent {i}")
            ax.scatter(*q[0, i, :3], marker="x", color=line.get_color())
            ax.scatter(*q[-1, i, :3], marker="o", color=line.get_color())
        for i, j in edges:
            ax.plot(*[[q[-1, i, c], q[-1, j, c]] for c in range(3)], color="0.4", lw=0.8)
        ax.set_zlabel("z [m]")
    else:
        ax = fig.add_subplot()
        for i in range(q.shape[1]):
            line, = ax.plot(q[:, i, 0], q[:, i, 1], label=f"agent {i}")
            ax.plot(q[0, i, 0], q[0, i, 1], "x", color=line.get_color())
            ax.plot(q[-1, i, 0], q[-1, i, 1], "o", color=line.get_color())
        for i, j in edges:
            ax.plot([q[-1, i, 0], q[-1, j, 0]], [q[-1, i, 1], q[-1, j, 1]], color="0.4", lw=0.8)
        ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(f"{title}: trajectories (x start, o end)")
    if q.shape[1] <= 8:
        ax.legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _plot_semilogy(path, title, t, y, ylabel, what):
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    positive = y > 0
    ax.semilogy(t[positive], y[positive])
    ax.set_xlabel("t [s]")
    ax.set_ylabel(ylabel)
    ax.set_title(f"{title}: {what}")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_energy(path, title, t, energy):
    _plot_semilogy(path, title, t, energy, "discrete energy E_d", "energy")


def plot_error(path, title, t, error):
    _plot_semilogy(path, title, t, error, "max |distance - desired| over edges [m]", "formation error")


def momentum_residuals(p, a, kappa, h):
    """Largest |X_k - e^{-kappa t_k} X_0| for X = P and A, absolute."""
    steps = np.arange(p.shape[0], dtype=float)
    res_p = np.linalg.norm(p - noether_prediction(p[0], kappa, h, steps), axis=1)
    res_a = np.linalg.norm(a - noether_prediction(a[0], kappa, h, steps), axis=1)
    return res_p, res_a


def plot_momenta(path, title, t, p, a, kappa, h):
    steps = np.arange(p.shape[0], dtype=float)
    res_p, res_a = momentum_residuals(p, a, kappa, h)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, x, res, name in ((axes[0], p, res_p, "linear |P|"), (axes[1], a, res_a, "angular |A|")):
        pred = np.linalg.norm(noether_prediction(x[0], kappa, h, steps), axis=1)
        positive = lambda y: np.where(y > 0, y, np.nan)  # exact zeros have no place on a log axis
        if np.any(pred > 0):
            ax.semilogy(t, positive(np.linalg.norm(x, axis=1)), label=name)
            ax.semilogy(t, positive(pred), "--", label="Noether: e^{-kappa t}|X_0|")
            ax.semilogy(t, positive(res), ":", label="|X_k - e^{-kappa t_k} X_0|")
        else:
            # A start at rest: the law says X_k = 0, so |X_k| is itself the residual.
            ax.semilogy(t, positive(np.linalg.norm(x, axis=1)), label=f"{name} (Noether: X_0 = 0, so X_k = 0)")
        ax.set_xlabel("t [s]")
        ax.set_title(f"{title}: {name}")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_all(out_dir, prefix, title, t, q, dimension, energy, error, p, a, kappa, h, edges=()):
    """Writes <prefix>_{trajectories,energy,error,momenta}.png and returns their paths."""
    os.makedirs(out_dir, exist_ok=True)
    paths = {name: os.path.join(out_dir, f"{prefix}_{name}.png")
             for name in ("trajectories", "energy", "error", "momenta")}
    plot_trajectories(paths["trajectories"], title, q, dimension, edges=edges)
    plot_energy(paths["energy"], title, t, energy)
    plot_error(paths["error"], title, t, error)
    plot_momenta(paths["momenta"], title, t, p, a, kappa, h)
    return paths


def summary(t, energy, error, p, a, kappa, h):
    """The demo's closing lines: final error, energy decay factor, momentum residuals."""
    res_p, res_a = momentum_residuals(p, a, kappa, h)
    scale_p = max(np.linalg.norm(p[0]), 1.0)
    scale_a = max(np.linalg.norm(a[0]), 1.0)
    return "\n".join([
        f"steps: {len(t) - 1}, final time {t[-1]:.3f} s",
        f"final formation error (max edge |distance - desired|): {error[-1]:.3e} m",
        f"energy decay factor E_final / E_0: {energy[-1] / energy[0]:.3e}"
        f" ({energy[0]:.6g} -> {energy[-1]:.6g})",
        f"Noether residual max_k |P_k - e^(-kappa t_k) P_0| / max(|P_0|, 1): {res_p.max() / scale_p:.3e}",
        f"Noether residual max_k |A_k - e^(-kappa t_k) A_0| / max(|A_0|, 1): {res_a.max() / scale_a:.3e}",
    ])
