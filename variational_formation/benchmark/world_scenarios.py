#!/usr/bin/python3
"""Every shipped scenario in both worlds (issue 33, item 5): robots.launch with world:=kinematic
(robot_sim) and world:=mujoco, holonomic and unicycle, recorded; the formation error by the
robots' own points, from the bag, at the scenario's end and some seconds later.

Error: the worst | |p_i - p_j| - s d_ij | over all pairs [m], p_i robot i's point (a unicycle's
hand point, hand_offset ahead of its axle at the odometry heading) averaged over one second of
the run's time (the monitor's status gives it), d_ij the desired distance and s the scale the
scenario's manoeuvre ends at (1 without one). Each run is the scenario with --extra seconds of
steps added (a copy in a temporary folder): identical up to the scenario's own end, it shows
whether the robots, which lag the agents, settle after it. "at the end" is the last second of
the scenario's own steps (of --cap seconds if it is longer: hexagon_steer runs 10 minutes),
"settled" the last second of the run. Contacts: the WorldContact messages the MuJoCo world
published (the bag records them). A run whose launch ends with an error (a 3D scenario in the
planar MuJoCo world, a unicycle in 3D) is listed with the launch's FATAL line.

usage: benchmark/world_scenarios.py [--scenarios NAME ...] [--worlds kinematic mujoco]
                                    [--kinematics holonomic unicycle] [--cap SECONDS]
                                    [--extra SECONDS] [--port P] [--keep DIR]
Needs the built workspace sourced (roslaunch finds the package). Prints one markdown table row
per run.
"""
import argparse
import glob
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
HAND_OFFSET = 0.1  # robots.launch's default


def yaw(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def final_scale(scenario):
    segments = scenario.get("manoeuvre") or []
    return float(segments[-1].get("scale", 1.0)) if segments else 1.0


def measure(bag_path, scenario, kinematics, ends):
    """(worst pair error over the second before each run time in `ends` [m] (None where a robot
    has no odometry there), contacts, first contact or None)."""
    import rosbag
    odom, contacts, start = {}, [], None
    with rosbag.Bag(bag_path) as bag:
        for topic, msg, t in bag.read_messages():
            if topic.endswith("/odom") and "/robot_" in topic:
                p = msg.pose.pose.position
                point = [p.x, p.y, p.z]
                if kinematics == "unicycle":
                    theta = yaw(msg.pose.pose.orientation)
                    point = [p.x + HAND_OFFSET * math.cos(theta), p.y + HAND_OFFSET * math.sin(theta), p.z]
                odom.setdefault(int(topic.split("/robot_")[1].split("/")[0]), []).append(
                    (msg.header.stamp.to_sec(), point))
            elif topic.endswith("/world/contacts"):
                contacts.append(msg)
            elif topic == "/formation/status" and start is None:
                start = msg.header.stamp.to_sec() - msg.time  # wall time of the run's t = 0
    n = len(scenario["agents"])
    desired = [a["desired_position"] for a in sorted(scenario["agents"], key=lambda a: a["id"])]
    s, d = final_scale(scenario), int(scenario["dimension"])
    errors = []
    for end in ends:
        windows = [[p for t, p in odom.get(i, []) if start is not None and end - 1.0 <= t - start <= end]
                   for i in range(n)]
        if not all(windows):
            errors.append(None)
            continue
        mean = [[sum(c) / len(w) for c in zip(*w)] for w in windows]
        errors.append(max(abs(math.dist(mean[a][:d], mean[b][:d]) - s * math.dist(desired[a], desired[b]))
                          for a in range(n) for b in range(a + 1, n)))
    first = f"t = {contacts[0].sim_time:.2f} s, {contacts[0].first} and {contacts[0].second}" if contacts else None
    return errors, len(contacts), first


def run(name, world, kinematics, cap, extra, port, out, keep=None):
    with open(os.path.join(HERE, "..", "config", name + ".yaml")) as f:
        scenario = yaml.safe_load(f)
    h = float(scenario["time_step"])
    shipped = min(scenario["steps"] * h, cap)
    scenario["steps"] = int(round((shipped + extra) / h))
    path = os.path.join(out, name + ".yaml")
    with open(path, "w") as f:
        yaml.safe_dump(scenario, f)
    env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{port}")
    log_path = os.path.join(out, f"{name}_{world}_{kinematics}.log")
    with open(log_path, "w") as log:
        launch = subprocess.Popen(["roslaunch", "-p", str(port), "variational_formation", "robots.launch",
                                   f"scenario:={path}", f"world:={world}", f"kinematics:={kinematics}",
                                   "record:=true", f"output_dir:={out}"], env=env, stdout=log,
                                  stderr=subprocess.STDOUT, start_new_session=True)
        try:
            launch.wait(timeout=shipped + extra + 90.0)
        except subprocess.TimeoutExpired:
            os.killpg(launch.pid, signal.SIGINT)
            launch.wait()
    with open(log_path) as f:
        text = f.read()
    fatal = re.search(r"FATAL[^\n]*", text) or re.search(r"(?m)^.*[Ee]rror:.*$", text)
    bag = os.path.join(out, name + ".bag")
    result_file = os.path.join(out, name + ".result.yaml")
    result = {}
    if os.path.exists(result_file):
        with open(result_file) as f:
            result = yaml.safe_load(f) or {}
    cells = [name, world, kinematics]
    if not os.path.exists(bag):
        return "| " + " | ".join(cells + [f"did not run: {fatal[0].strip() if fatal else 'no bag'}", "", "", ""]) + " |"
    errors, contacts, first = measure(bag, scenario, kinematics, [shipped, shipped + extra])
    for leftover in (bag, result_file):
        if keep and os.path.exists(leftover):
            shutil.move(leftover, os.path.join(keep, f"{name}_{world}_{kinematics}{os.path.splitext(leftover)[1]}"))
        elif os.path.exists(leftover):
            os.remove(leftover)
    shown = [f"{e * 1000:.2f} mm" if e is not None else "(no odometry)" for e in errors]
    contact_text = "(not simulated)" if world == "kinematic" else f"{contacts}" + (f" (first {first})" if first else "")
    return "| " + " | ".join(cells + shown + [str(result.get("result", "no result")), contact_text]) + " |"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    names = sorted(os.path.basename(p)[:-5] for p in glob.glob(os.path.join(HERE, "..", "config", "*.yaml")))
    parser.add_argument("--scenarios", nargs="+", default=names)
    parser.add_argument("--worlds", nargs="+", default=["kinematic", "mujoco"])
    parser.add_argument("--kinematics", nargs="+", default=["holonomic", "unicycle"])
    parser.add_argument("--cap", type=float, default=30.0)
    parser.add_argument("--extra", type=float, default=10.0)
    parser.add_argument("--port", type=int, default=11650)
    parser.add_argument("--keep", default=None, help="a folder to keep the bags and result files in")
    args = parser.parse_args()
    out = tempfile.mkdtemp(prefix="vf_world_scenarios_")
    print("| scenario | world | kinematics | error at the end | settled (+ extra) | result | contacts |", flush=True)
    print("| --- | --- | --- | --- | --- | --- | --- |", flush=True)
    try:
        for name in args.scenarios:
            for kinematics in args.kinematics:
                for world in args.worlds:
                    print(run(name, world, kinematics, args.cap, args.extra, args.port, out, args.keep), flush=True)
    finally:
        shutil.rmtree(out, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
