"""Plots of a formation run, shared by the CSV (plot_simulation.py) and bag (plot_bag.py) front-ends.

Every function takes plain numpy arrays:
  t[k]            time of step k [s]
  q[k, i, a]      position of agent i at step k (a = x, y, z)
  energy[k]       discrete energy
  error[k]        largest edge distance error [m]
  p[k, 3], a[k, 3] total linear and angular momentum
"""
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def noether_prediction(initial, kappa, h, steps):
    """e^{-kappa t_k} X_0, formed as (e^{-kappa h})^k (doc/maths.md: never e^{kappa t})."""
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


def plot_manoeuvre(path, title, t, q, edges, commanded_velocity, instants=5):
    """The centroid's path against the commanded one (the initial centroid moved by the commanded
    v*, interval by interval), and the shape at a few instants (2D, or the x-y view in 3D)."""
    h = t[1] - t[0] if len(t) > 1 else 1.0
    centroid = q.mean(axis=1)
    commanded = centroid[0] + np.vstack([np.zeros(3), np.cumsum(commanded_velocity * h, axis=0)])
    fig, ax = plt.subplots(figsize=(7.0, 5.6))
    ax.plot(commanded[:, 0], commanded[:, 1], "--", color="0.3", lw=2.0, label="commanded centroid path")
    ax.plot(centroid[:, 0], centroid[:, 1], color="tab:red", lw=1.0, label="centroid")
    for n, k in enumerate(np.linspace(0, len(t) - 1, instants).astype(int)):
        colour = plt.cm.viridis(n / max(instants - 1, 1))
        for i, j in edges:
            ax.plot([q[k, i, 0], q[k, j, 0]], [q[k, i, 1], q[k, j, 1]], color=colour, lw=1.0)
        ax.plot(q[k, :, 0], q[k, :, 1], "o", ms=3, color=colour)
        ax.annotate(f"t = {t[k]:.1f} s", centroid[k, :2], textcoords="offset points", xytext=(4, -12),
                    fontsize="small", color=colour)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(f"{title}: centroid path and shape")
    ax.legend(fontsize="small", loc="best")
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


def plot_separation(path, title, t, separation, radius):
    """The closest pair's distance at each step against the safety radius r (doc/maths.md §10):
    the filter keeps the curve above the line."""
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.plot(t, separation, label="closest pair")
    ax.axhline(radius, color="red", linestyle="--", label=f"r = {radius:g} m")
    finite = separation[np.isfinite(separation)]
    if finite.size:
        ax.set_ylim(0.0, max(2.0 * radius, 1.1 * float(np.max(finite))))
    ax.set_xlabel("t [s]")
    ax.set_ylabel("min separation [m]")
    ax.set_title(f"{title}: separation")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def add_separation(paths, out_dir, prefix, title, t, separation, radius):
    """<prefix>_separation.png into `paths` when the run had a safety filter (radius not None and
    some separation measured)."""
    if radius is None or not np.any(np.isfinite(separation)):
        return
    paths["separation"] = os.path.join(out_dir, f"{prefix}_separation.png")
    plot_separation(paths["separation"], title, t, separation, radius)


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


def plot_region_of_attraction(path, cells, scenario, agent, h):
    """Heatmap of roa.csv rows `cells` (ix, iy, x, y, converged, converged_step, diverged):
    convergence time in colour, not converged grey, diverged black, the desired shape on top."""
    from matplotlib.colors import ListedColormap

    desired = scenario.desired
    ix, iy = cells[:, 0].astype(int), cells[:, 1].astype(int)
    nx, ny = ix.max() + 1, iy.max() + 1
    time = np.full((ny, nx), np.nan)
    status = np.zeros((ny, nx))  # 0 converged, 1 not converged, 2 diverged
    conv = cells[:, 4] == 1
    time[iy[conv], ix[conv]] = cells[conv, 5] * h
    status[iy[~conv], ix[~conv]] = 1
    status[iy[cells[:, 6] == 1], ix[cells[:, 6] == 1]] = 2
    x, y = cells[:, 2], cells[:, 3]
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
    for i, j in scenario.edges:
        ax.plot(desired[[i, j], 0], desired[[i, j], 1], color="white", lw=1.5)
        ax.plot(desired[[i, j], 0], desired[[i, j], 1], color="red", lw=0.8)
    ax.plot(desired[:, 0], desired[:, 1], "o", color="red", ms=5)
    ax.plot(*desired[agent, :2], "o", mfc="none", mec="white", ms=12, mew=2)
    ax.set_xlim(extent[0], extent[1])
    ax.set_ylim(extent[2], extent[3])
    ax.set_xlabel("x of agent %d at start [m]" % agent)
    ax.set_ylabel("y of agent %d at start [m]" % agent)
    ax.set_title(f"{scenario.name}: region of attraction of agent {agent}\n"
                 f"{len(cells)} cells: {100 * conv.mean():.1f}% converged (colour), "
                 f"{100 * (status == 1).mean():.1f}% not (grey), "
                 f"{100 * (status == 2).mean():.1f}% diverged (black)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_method_comparison(path, title, runs, dimension):
    """One row per method: each run's trajectories (x = start; points beyond 1e3 m left out)
    and, last, E / E_0 of every run of that method. `runs` holds, in rows of equal length,
    (method label, h, q[k, i, 0:3], t, energy, bounded)."""
    labels = list(dict.fromkeys(r[0] for r in runs))
    columns = len(runs) // len(labels)
    fig = plt.figure(figsize=(4 * (columns + 1), 3.75 * len(labels)))
    for r, label in enumerate(labels):
        mine = [run for run in runs if run[0] == label]
        energy_ax = fig.add_subplot(len(labels), columns + 1, r * (columns + 1) + columns + 1)
        for c, (_, h, q, t, energy, bounded) in enumerate(mine):
            ax = fig.add_subplot(len(labels), columns + 1, r * (columns + 1) + c + 1,
                                 projection="3d" if dimension == 3 else None)
            for i in range(q.shape[1]):
                ok = np.all(np.isfinite(q[:, i]), axis=1) & (np.abs(q[:, i]).max(axis=1) < 1e3)
                track = [q[ok, i, a] for a in range(dimension)]
                line, = ax.plot(*track, lw=1)
                ax.plot(*[[q[0, i, a]] for a in range(dimension)], "x", color=line.get_color())
            ax.set_title(f"{label}, h = {h}" + ("" if bounded else " (diverged)"), fontsize=9)
            if dimension == 2:
                ax.set_aspect("equal", adjustable="datalim")
            good = np.isfinite(energy) & (energy > 0)
            energy_ax.semilogy(t[good], energy[good] / energy[0], label=f"h = {h}")
        energy_ax.set_title(f"{label}: E / E_0", fontsize=9)
        energy_ax.set_xlabel("t [s]")
        energy_ax.set_ylim(1e-12, 1e3)
        energy_ax.legend(fontsize="small")
        energy_ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(f"{title} (x = start)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
