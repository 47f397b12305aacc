#!/usr/bin/python3
"""rostest (timed_bad_input.test): a timed agent with a bad parameter, and make_agents_launch.py
with a bad timed argument, each end with exit status 2 and one line on stderr naming the field
and the value."""
import os
import signal
import subprocess
import sys
import time
import unittest

import rospkg
import rospy
import rostest
from rosgraph_msgs.msg import Log

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402

HEXAGON = vf_rostest.scenario_path("hexagon")


def run(command):
    p = subprocess.run(command, capture_output=True, text=True, timeout=30)
    return p.returncode, [line for line in p.stderr.splitlines() if line.strip()]


@vf_rostest.reported_setup
class TimedBadInput(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("timed_bad_input_test")
        cls.script = os.path.join(rospkg.RosPack().get_path(vf_rostest.PKG), "scripts", "make_agents_launch.py")

    def agent(self, name, **params):
        base = {"id": "0", "scenario": HEXAGON, "mode": "timed", "real_time_factor": "1"}
        base.update(params)
        return run(["rosrun", vf_rostest.PKG, "agent", f"__name:={name}", "__ns:=/bad"] +
                   [f"_{k}:={v}" for k, v in base.items()])

    def check(self, result, *words):
        status, lines = result
        self.assertEqual(status, 2, lines)
        self.assertEqual(len(lines), 1, lines)
        for w in words:
            self.assertIn(w, lines[0])

    def test_negative_delay(self):
        self.check(self.agent("agent_neg_delay", delay="-0.05"), "delay", "-0.05")

    def test_loss_above_one(self):
        self.check(self.agent("agent_loss", loss="1.5"), "loss", "1.5")

    def test_negative_loss(self):
        self.check(self.agent("agent_neg_loss", loss="-0.1"), "loss", "-0.1")

    def test_timed_needs_a_rate(self):
        self.check(self.agent("agent_rate", real_time_factor="0"), "real_time_factor", "> 0")

    def test_unknown_mode(self):
        self.check(self.agent("agent_mode", mode="fast"), "mode", "fast")

    def test_launch_arguments(self):
        base = [self.script, "--scenario", HEXAGON, "--out", "/dev/null", "--mode", "timed", "--rate", "1"]
        self.check(run(base + ["--delay", "-1"]), "delay", "-1")
        self.check(run(base + ["--loss", "1.5"]), "loss", "1.5")
        self.check(run(base + ["--loss", "-0.2"]), "loss", "-0.2")
        self.check(run(base[:-2] + ["--rate", "0"]), "rate", "timed")

    def test_missing_odometry_holds_and_says_so(self):
        # A robot-mode agent whose odom topic has no publisher: it stays up, holds, and says so
        # every few seconds (no monitor either: it would not start anyway).
        lines = []
        sub = rospy.Subscriber("/rosout", Log, lambda m: lines.append(m) if m.name == "/lonely/agent_0" else None,
                               queue_size=1000)
        p = subprocess.Popen(["rosrun", vf_rostest.PKG, "agent", "__name:=agent_0", "__ns:=/lonely", "_id:=0",
                              f"_scenario:={HEXAGON}", "_mode:=timed", "_real_time_factor:=1", "_robot:=true",
                              "~odom:=/nobody/odom"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            time.sleep(12.0)
            self.assertIsNone(p.poll(), "the agent ended without odometry")
        finally:
            p.send_signal(signal.SIGINT)
            p.wait(timeout=20)
            sub.unregister()
        said = [m.msg for m in lines if "no odometry on /nobody/odom" in m.msg]
        self.assertTrue(2 <= len(said) <= 4, f"{len(said)} lines: {[m.msg for m in lines]}")


if __name__ == "__main__":
    rostest.rosrun(vf_rostest.PKG, "timed_bad_input", TimedBadInput)
