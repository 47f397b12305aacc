#!/usr/bin/python3
"""Reads one nav_msgs/Odometry message from each robot of a scenario and writes their positions
as the start positions file assign_slots reads (agent,x,y,z).

usage: rosrun variational_formation odom_starts.py --scenario FILE|NAME --out starts.csv
                                                   [--ns formation] [--timeout 10] [--world-frame world]
       rosrun variational_formation assign_slots --scenario FILE|NAME --starts starts.csv --out assigned.yaml

Robot i's odometry is <ns>/robot_<i>/odom, as robots.launch names it (robot_sim or a real robot's
driver remapped there). Its header.frame_id must be the world frame (--world-frame, as the
launch's world_frame; a leading '/' ignored): odometry in another frame (a TurtleBot3's own odom,
where every robot starts at 0, 0) is refused with one warning per topic naming both frames, and
counted; it waits on for odometry in the world frame, and fails after --timeout with the count.
"""
import argparse
import subprocess
import sys
import threading
import time

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


def bare(frame):
    return frame[1:] if frame.startswith("/") else frame


class WorldOdometry:
    """The first odometry message in the world frame on a topic; others refused and counted."""

    def __init__(self, topic, world_frame):
        self.topic, self.world_frame = topic, world_frame
        self.found, self.refused, self.frames = None, 0, set()
        self.ready = threading.Event()
        self.sub = rospy.Subscriber(topic, Odometry, self.on_odometry, queue_size=10)

    def on_odometry(self, msg):
        if self.ready.is_set():
            return
        if bare(msg.header.frame_id) != bare(self.world_frame):
            self.refused += 1
            self.frames.add(msg.header.frame_id)
            if self.refused == 1:
                print(f"odom_starts: warning: refused odometry on {self.topic} in frame '{msg.header.frame_id}', "
                      f"not the world frame '{self.world_frame}' (positions are taken as world positions); "
                      "waiting for odometry in the world frame", file=sys.stderr, flush=True)
            return
        self.found = msg
        self.ready.set()

    def wait(self, deadline, timeout):
        """The message, or exit 2 if none came by `deadline` (time.monotonic(), `timeout` s from the start)."""
        got = self.ready.wait(max(0.0, deadline - time.monotonic()))
        self.sub.unregister()
        if not got:
            refused = (f" ({self.refused} refused in frame '{sorted(self.frames)[0]}'"
                       f"{' and others' if len(self.frames) > 1 else ''})" if self.refused else "")
            fail(f"no odometry in the world frame '{self.world_frame}' on {self.topic} within {timeout:g} s{refused}")
        return self.found


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     usage="odom_starts.py --scenario FILE|NAME --out starts.csv [--ns NS] [--timeout S] "
                                           "[--world-frame FRAME]")
    parser.add_argument("--scenario", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--ns", default="formation")
    parser.add_argument("--timeout", type=float, default=10.0, help="seconds to wait for each robot [s]")
    parser.add_argument("--world-frame", default="world", help="the frame the odometry must be in (the launch's world_frame)")
    args = parser.parse_args(rospy.myargv()[1:])
    if not args.timeout > 0:
        fail(f"--timeout: must be > 0 s, got {args.timeout:g}")
    if not args.world_frame.strip("/") or any(c.isspace() for c in args.world_frame):
        fail(f"--world-frame: expected a frame name without spaces, got '{args.world_frame}'")
    n = agent_count(args.scenario)
    rospy.init_node("odom_starts", anonymous=True)
    topics = [f"{args.ns.rstrip('/')}/robot_{i}/odom" if args.ns else f"robot_{i}/odom" for i in range(n)]
    # Every robot's subscriber at once: each gets --timeout from now.
    waits = [WorldOdometry(topic, args.world_frame) for topic in topics]
    deadline = time.monotonic() + args.timeout
    rows = []
    for i, w in enumerate(waits):
        p = w.wait(deadline, args.timeout).pose.pose.position
        rows.append(f"{i},{p.x!r},{p.y!r},{p.z!r}")  # assign_slots refuses z != 0 in 2D
    with open(args.out, "w") as f:
        f.write("agent,x,y,z\n" + "\n".join(rows) + "\n")
    print(f"odom_starts: {n} positions written to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
