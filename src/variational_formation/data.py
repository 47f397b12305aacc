"""The files the tools write and read, as numpy arrays (formats: doc/architecture.md).

Arrays follow one layout:
  q[k, i, a]   position of agent i at step k (a = x, y, z; z = 0 in 2D) [m]
"""
import types

import numpy as np
import yaml

from variational_formation.cli import fail

TRAJECTORY_HEADER = "step,t,agent,x,y,z"
METRICS_HEADER = "step,t,energy,max_distance_error,px,py,pz,ax,ay,az"
ROA_HEADER = "ix,iy,x,y,converged,converged_step,diverged"


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


def read_trajectory(path, agents=None):
    """simulate's traj.csv as q[k, i, 0:3]. `agents` defaults to the count found in the file."""
    rows = load_csv(path, TRAJECTORY_HEADER)
    if rows.shape[0] == 0:
        fail(f"{path}: no rows")
    n = agents if agents is not None else int(rows[:, 2].max()) + 1
    if rows.shape[0] % n != 0:
        fail(f"{path}: {rows.shape[0]} rows is not a multiple of {n} agents")
    return rows[:, 3:6].reshape(rows.shape[0] // n, n, 3)


def read_metrics(path):
    """simulate's metrics.csv: t, energy, max_distance_error, p[k, 3] and a[k, 3]."""
    m = load_csv(path, METRICS_HEADER)
    return types.SimpleNamespace(t=m[:, 1], energy=m[:, 2], error=m[:, 3], p=m[:, 4:7], a=m[:, 7:10])


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
