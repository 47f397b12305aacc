#!/usr/bin/python3
"""Records a timed or robot-mode run: everything published under the formation's namespace (the
agents' states and poses, the monitor's status, markers and progress, and the robots' odom,
cmd_vel and setpoint when they live there) and /tf, /tf_static, with rosbag record.

formation.launch starts it as the node `recorder` in the formation's namespace when record:=true
and mode:=timed (lockstep runs use the lossless recorder node instead). It is rosbag record
itself once started (it replaces this process), so a SIGINT or `rosnode kill` closes the bag.

usage: record_formation.py --bag PATH [--topics TOPIC ...]
  --bag      the bag to write; {ns} is replaced as in the recorder's ~bag (team_a_ for a formation
             in /team_a/formation); an existing bag is replaced with one warning line
  --topics   more topics to record (e.g. robots' odometry outside the formation's namespace)
Bad input: one line on stderr, exit status 2.
"""
import argparse
import os
import re
import sys

import roslib.packages


def fail(message):
    print(f"record_formation.py: error: {message}", file=sys.stderr)
    sys.exit(2)


def node_namespace(argv):
    """The namespace roslaunch gave this node (__ns:=), else ROS_NAMESPACE, else /."""
    ns = next((a.split(":=", 1)[1] for a in argv if a.startswith("__ns:=")), os.environ.get("ROS_NAMESPACE", "/"))
    ns = "/" + ns.strip("/")
    return ns


def file_prefix(ns):
    """The namespace holding the formation, as a file-name prefix: /team_a/formation -> team_a_."""
    holder = ns.rsplit("/", 1)[0].strip("/")
    return holder.replace("/", "_") + "_" if holder else ""


def main():
    ros_args = [a for a in sys.argv[1:] if ":=" in a]
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--bag", required=True)
    parser.add_argument("--topics", nargs="*", default=[])
    parser.error = lambda message: fail(message.replace("argument --", ""))
    args = parser.parse_args([a for a in sys.argv[1:] if ":=" not in a])
    ns = node_namespace(sys.argv[1:])
    path = args.bag.replace("{ns}", file_prefix(ns))
    if not path.endswith(".bag"):
        fail(f"bag: expected a file name ending in .bag, got '{path}'")
    try:
        os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    except OSError as e:
        fail(f"bag: cannot create the folder of {path}: {e.strerror}")
    if os.path.exists(path):
        print(f"record_formation.py: replacing the bag of an earlier run {path}", file=sys.stderr)
    record = roslib.packages.find_node("rosbag", "record")
    if not record:
        fail("rosbag's record program is not installed (Debian package rosbag)")
    # Everything below the formation's namespace; /tf for the agents' and robots' frames.
    pattern = "^" + re.escape(ns.rstrip("/")) + "/.*" if ns != "/" else ".*"
    # With -e every topic argument is a regular expression.
    topics = [pattern, "^/tf$", "^/tf_static$"] + ["^" + re.escape(t) + "$" for t in args.topics]
    # robot_sim's ground_truth is the true pose that /tf already holds: left out.
    command = [record[0], "-O", path, "-e"] + topics + ["-x", ".*/ground_truth$"] + ros_args
    os.execv(record[0], command)


if __name__ == "__main__":
    main()
