"""The files the tools write and read, as numpy arrays (formats: doc/architecture.md).

Arrays follow one layout:
  q[k, i, a]   position of agent i at step k (a = x, y, z; z = 0 in 2D) [m]
"""
import os
import types

import numpy as np
import yaml

from variational_formation.cli import fail

TRAJECTORY_HEADER = "step,t,agent,x,y,z"
METRICS_HEADER = ("step,t,energy,max_distance_error,px,py,pz,ax,ay,az,"
                  "cvx,cvy,cvz,wx,wy,wz,scale_error,shape_error")
# metrics.csv as simulate wrote it before the shape error; still read (shape_error = NaN).
METRICS_HEADER_WITHOUT_SHAPE = METRICS_HEADER[:-len(",shape_error")]
# metrics.csv of a run with a safety: filter: one more column, the closest pair at each step.
METRICS_HEADER_WITH_SEPARATION = METRICS_HEADER + ",min_separation"
# metrics.csv as simulate wrote it before the tracking columns; still read (tracking = NaN).
METRICS_HEADER_WITHOUT_TRACKING = "step,t,energy,max_distance_error,px,py,pz,ax,ay,az"
COMMANDS_HEADER = "step,vx,vy,vz,wx,wy,wz,scale"
ROA_HEADER = "ix,iy,x,y,converged,converged_step,diverged"


def load_csv(path, header, *older_headers):
    """The rows of a CSV file whose first line must be `header` (or one of `older_headers`), as a
    2D array; fail() if not."""
    try:
        with open(path) as f:
            first = f.readline().strip()
        if first != header and first not in older_headers:
            fail(f"{path}: expected header '{header}', got '{first}'")
        return np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    except (OSError, ValueError) as e:
        fail(f"{path}: {e}")


def read_trajectory(path, agents=None, dimension=None, scenario_name="the scenario"):
    """simulate's traj.csv as q[k, i, 0:3]. `agents` defaults to the count found in the file;
    given (with `dimension`, from the scenario), a file of another formation is an error."""
    rows = load_csv(path, TRAJECTORY_HEADER)
    if rows.shape[0] == 0:
        fail(f"{path}: no rows")
    found = int(rows[:, 2].max()) + 1
    n = agents if agents is not None else found
    if found != n:
        fail(f"{path}: the trajectory has {found} agents, {scenario_name} has {n}: they do not belong together")
    if rows.shape[0] % n != 0 or not np.array_equal(rows[:, 2], np.tile(np.arange(n), rows.shape[0] // n)):
        fail(f"{path}: rows are not agents 0..{n - 1} step after step")
    if dimension == 2 and np.any(rows[:, 5] != 0):
        fail(f"{path}: the trajectory leaves the plane z = 0, {scenario_name} is 2D: they do not belong together")
    return rows[:, 3:6].reshape(rows.shape[0] // n, n, 3)


def bag_parts(path):
    """A bag and the later parts of its recording (<stem>_1.bag, <stem>_2.bag, ...: the
    recorder's record_split_size), in order."""
    parts, stem = [path], path[:-len(".bag")] if path.endswith(".bag") else path
    while os.path.exists(f"{stem}_{len(parts)}.bag"):
        parts.append(f"{stem}_{len(parts)}.bag")
    return parts


def read_metrics(path):
    """simulate's metrics.csv: t, energy, max_distance_error, p[k, 3], a[k, 3], and the tracking
    columns: centroid velocity cv[k, 3], rotation rate w[k, 3], mean scale error scale_error[k], the
    shape error over all pairs shape_error[k], and min_separation[k] (the closest pair; NaN without
    a safety: filter)."""
    m = load_csv(path, METRICS_HEADER, METRICS_HEADER_WITH_SEPARATION, METRICS_HEADER_WITHOUT_SHAPE,
                 METRICS_HEADER_WITHOUT_TRACKING)
    if m.shape[1] < 19:
        m = np.hstack([m, np.full((m.shape[0], 19 - m.shape[1]), np.nan)])
    return types.SimpleNamespace(t=m[:, 1], energy=m[:, 2], error=m[:, 3], p=m[:, 4:7], a=m[:, 7:10],
                                 cv=m[:, 10:13], w=m[:, 13:16], scale_error=m[:, 16], shape_error=m[:, 17],
                                 min_separation=m[:, 18])


def commanded_velocities(scenario_path, steps, h, commands=None):
    """v*[k, 3] of interval k (doc/manoeuvres.md): from a commands file if given, else from the
    scenario's `manoeuvre:` (segment in force at t_k = k h); None if there is no command."""
    v = np.zeros((steps, 3))
    if commands:
        rows = load_csv(commands, COMMANDS_HEADER)
        for row in rows:
            v[int(row[0]):] = row[1:4]
        return v
    try:
        with open(scenario_path) as f:
            segments = yaml.safe_load(f).get("manoeuvre")
    except (OSError, yaml.YAMLError, AttributeError) as e:
        fail(f"{scenario_path}: cannot read the manoeuvre ({e})")
    if not segments:
        return None
    t = np.arange(steps) * h
    chosen = np.full(steps, len(segments) - 1)
    for s in reversed(range(len(segments))):
        if "until" in segments[s]:
            chosen[t < float(segments[s]["until"])] = s
    for s, segment in enumerate(segments):
        velocity = list(segment.get("velocity") or [])
        v[chosen == s, :len(velocity)] = velocity
    return v


def scenario_folders():
    """Where a scenario name is looked up, in the order of the C++ tools (tools/scenario_path.hpp):
    the package's config/ in each entry of ROS_PACKAGE_PATH, then beside this package: the
    source checkout (src/variational_formation -> config/) or the install space
    (<prefix>/lib/python3/dist-packages/variational_formation -> <prefix>/share/.../config)."""
    folders = []
    for entry in os.environ.get("ROS_PACKAGE_PATH", "").split(":"):
        entry = entry.rstrip("/")
        if entry:
            package = entry if os.path.basename(entry) == "variational_formation" else os.path.join(
                entry, "variational_formation")
            folders.append(os.path.join(package, "config"))
    here = os.path.dirname(os.path.abspath(__file__))
    folders.append(os.path.normpath(os.path.join(here, "..", "..", "config")))
    folders.append(os.path.normpath(os.path.join(here, "..", "..", "..", "..", "share", "variational_formation",
                                                 "config")))
    return list(dict.fromkeys(folders))


def scenario_path(name_or_path):
    """The scenario file meant by a --scenario, as the launch files and the C++ tools read it: a
    path that exists wins; a bare name ("hexagon", "hexagon.yaml") is <name>.yaml in the first of
    scenario_folders() that has it; another path is returned as it is. fail() if a bare name is
    found nowhere, listing the places."""
    if os.path.isfile(name_or_path) or "/" in name_or_path or not name_or_path:
        return name_or_path
    file = name_or_path if name_or_path.endswith(".yaml") else name_or_path + ".yaml"
    folders = scenario_folders()
    for folder in folders:
        if os.path.isfile(os.path.join(folder, file)):
            return os.path.join(folder, file)
    fail(f"scenario '{name_or_path}': no such file, and no {file} in {', '.join(folders)}")


def read_scenario(name_or_path):
    """The fields of a scenario (a file, or a name: scenario_path) that the plots use, already
    checked by the package's loader: name, dimension, kappa, time_step, n, desired (n x d
    array), edges, and safety_radius (the safety block's r, None without one)."""
    path = scenario_path(name_or_path)
    try:
        with open(path) as f:
            s = yaml.safe_load(f)
        agents = s["agents"]
        return types.SimpleNamespace(
            name=str(s.get("name", "")), dimension=int(s["dimension"]), kappa=float(s["kappa"]),
            time_step=float(s["time_step"]), n=len(agents),
            desired=np.array([a["desired_position"] for a in agents], float),
            edges=[tuple(e) for e in s.get("edges") or []],
            safety_radius=float(s["safety"]["radius"]) if s.get("safety") else None)
    except (OSError, yaml.YAMLError, KeyError, TypeError, ValueError, AttributeError) as e:
        fail(f"{path}: cannot read the scenario ({e})")
