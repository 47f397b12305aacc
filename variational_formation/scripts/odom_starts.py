#!/usr/bin/python3
"""Reads one nav_msgs/Odometry message from each robot of a scenario and writes their positions
as the start positions file assign_slots reads (agent,x,y,z).

usage: rosrun variational_formation odom_starts.py --scenario FILE|NAME --out starts.csv
                                                   [--ns formation] [--timeout 10]
       rosrun variational_formation assign_slots --scenario FILE|NAME --starts starts.csv --out assigned.yaml

Robot i's odometry is <ns>/robot_<i>/odom, as robots.launch names it (robot_sim or a real robot's
driver remapped there). The positions are taken in the odometry's own frame, which must be the
scenario's world frame.
"""
import argparse
import subprocess
import sys

import rospy
from nav_msgs.msg import Odometry


def fail(message):
    print(f"odom_starts: error: {message}", file=sys.stderr)
    sys.exit(2)


def agent_count(scenario):
    """n and the dimension, through the package's one loader (scenario_info)."""
    info = subprocess.run(["rosrun", "variational_formation", "scenario_info", "--scenario", scenario],
                          capture_output=True, text=True)
    if info.returncode != 0:
        lines = info.stderr.strip().splitlines() or ["scenario_info failed"]
        fail(lines[-1].replace("scenario_info: error: ", ""))
    return int(info.stdout.split()[1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     usage="odom_starts.py --scenario FILE|NAME --out starts.csv [--ns NS] [--timeout S]")
    parser.add_argument("--scenario", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--ns", default="formation")
    parser.add_argument("--timeout", type=float, default=10.0, help="seconds to wait for each robot [s]")
    args = parser.parse_args(rospy.myargv()[1:])
    n = agent_count(args.scenario)
    rospy.init_node("odom_starts", anonymous=True)
    rows = []
    for i in range(n):
        topic = f"{args.ns.rstrip('/')}/robot_{i}/odom" if args.ns else f"robot_{i}/odom"
        try:
            msg = rospy.wait_for_message(topic, Odometry, timeout=args.timeout)
        except rospy.ROSException:
            fail(f"no odometry on {topic} within {args.timeout} s")
        p = msg.pose.pose.position
        rows.append(f"{i},{p.x!r},{p.y!r},{p.z!r}")  # assign_slots refuses z != 0 in 2D
    with open(args.out, "w") as f:
        f.write("agent,x,y,z\n" + "\n".join(rows) + "\n")
    print(f"odom_starts: {n} positions written to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
