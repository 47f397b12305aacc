#!/usr/bin/python3
"""rostest (timed_bad_input.test): a timed agent or robot_sim with a bad parameter, and
make_agents_launch.py with a bad timed or robot argument, each end with exit status 2 and one line
on stderr naming the field and the value. Odometry that is not a pose (a NaN, a quaternion that is
not a rotation), sent by this test's own node, is dropped, counted and warned about by a
robot-mode agent, which stays up. A monitor measuring robots (~measure_robots) refuses bad settings
in one line, and drops such odometry the same way, names the robots whose odometry it waits for,
and stays up. Odometry in another frame than the world frame (a TurtleBot3's own odom, each robot
at 0, 0 of its own frame) is refused with one WARN naming both frames and counted, by the agent
(which holds; its diagnostics count it), the monitor (which does not measure that robot) and
odom_starts.py (which waits on, then fails with the count)."""
import contextlib
import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import rospkg
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Log

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402

HEXAGON = vf_rostest.scenario_path("hexagon")


@contextlib.contextmanager
def robot_agent(ns, *params):
    """A robot-mode timed agent agent_0 in `ns` while the block runs; yields (process, its /rosout
    lines). On leaving: SIGINT, and the agent must end."""
    lines = []
    sub = rospy.Subscriber("/rosout", Log, lambda m: lines.append(m) if m.name == f"{ns}/agent_0" else None,
                           queue_size=1000)
    p = subprocess.Popen(["rosrun", vf_rostest.PKG, "agent", "__name:=agent_0", f"__ns:={ns}", "_id:=0",
                          f"_scenario:={HEXAGON}", "_mode:=timed", "_real_time_factor:=1", "_robot:=true"] +
                         list(params), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        yield p, lines
    finally:
        p.send_signal(signal.SIGINT)
        p.wait(timeout=20)
        sub.unregister()


def odometry(frame, x=0.0, y=0.0):
    """A pose at (x, y), heading 0, in `frame`."""
    msg = Odometry()
    msg.header.frame_id = frame
    msg.header.stamp = rospy.Time.now()
    msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
    msg.pose.pose.orientation.w = 1.0
    return msg


def wait_for_subscriber(test, pub, who):
    end = time.time() + 20
    while pub.get_num_connections() == 0 and time.time() < end:
        time.sleep(0.1)
    test.assertEqual(pub.get_num_connections(), 1, f"{who} never subscribed to {pub.resolved_name}")


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

    def test_negative_hand_offset(self):
        self.check(self.agent("agent_hand", robot="true", kinematics="unicycle", hand_offset="-0.1"),
                   "hand_offset", "-0.1")

    def test_unknown_kinematics(self):
        self.check(self.agent("agent_tank", robot="true", kinematics="tank"), "kinematics", "tank")

    def test_unicycle_needs_the_plane(self):
        self.check(self.agent("agent_3d", robot="true", kinematics="unicycle",
                              scenario=vf_rostest.scenario_path("tetrahedron")), "kinematics", "plane")

    def test_robot_sim_bad_parameters(self):
        # A list cannot be given as _param:= to a C++ node.
        for name in ("sim_tank", "sim_hand"):
            rospy.set_param(f"/bad/robot_0/{name}/initial_position", [0.0, 0.0])
        base = ["rosrun", vf_rostest.PKG, "robot_sim", "__ns:=/bad/robot_0", "_id:=0"]
        self.check(run(base + ["__name:=sim_tank", "_kinematics:=tank"]), "kinematics", "tank")
        self.check(run(base + ["__name:=sim_hand", "_kinematics:=unicycle", "_hand_offset:=-0.2"]), "hand_offset",
                   "-0.2")

    def test_robot_launch_arguments(self):
        base = [self.script, "--scenario", HEXAGON, "--out", "/dev/null", "--mode", "timed", "--rate", "1",
                "--robot", "true"]
        self.check(run(base + ["--kinematics", "tank"]), "kinematics", "tank")
        self.check(run(base + ["--hand-offset", "-0.1"]), "hand_offset", "-0.1")
        self.check(run(base + ["--feedback", "gps"]), "feedback", "gps")

    def test_malformed_odometry_is_dropped_counted_and_warned(self):
        pub = rospy.Publisher("/odd_robot/odom", Odometry, queue_size=10)
        with robot_agent("/odd", "_kinematics:=unicycle", "_robot_namespace:=/odd_robot") as (p, lines):
            wait_for_subscriber(self, pub, "the agent")
            nan = odometry("world", x=float("nan"))
            squashed = odometry("world")  # quaternion of norm 0.5: not a rotation
            squashed.pose.pose.orientation.w = 0.5
            for _ in range(3):
                pub.publish(nan)
                time.sleep(1.1)  # the warning is throttled to one a second
                pub.publish(squashed)
                time.sleep(1.1)
            time.sleep(6.0)  # until it says again that it holds without odometry
            self.assertIsNone(p.poll(), "the agent ended on malformed odometry")
        dropped = [m.msg for m in lines if "dropped an odometry message" in m.msg]
        self.assertTrue(any("must be finite" in m for m in dropped), dropped)
        self.assertTrue(any("norm 1" in m for m in dropped), dropped)
        self.assertTrue(any(m.endswith("6 dropped so far") for m in dropped), dropped)
        # Nothing was taken for a pose: it still holds for want of odometry.
        self.assertTrue(any("no odometry on /odd_robot/odom" in m.msg for m in lines[-20:]),
                        [m.msg for m in lines])
        self.assertFalse(any("first odometry" in m.msg for m in lines), [m.msg for m in lines])

    def test_odometry_in_another_frame_is_refused_once_counted_and_the_agent_holds(self):
        # A TurtleBot3's own odometry: frame odom, the robot at 0, 0 of it.
        pub = rospy.Publisher("/tb3_0/odom", Odometry, queue_size=10)
        diagnostics = []
        sub = rospy.Subscriber("/diagnostics", DiagnosticArray, lambda m: diagnostics.extend(
            {kv.key: kv.value for kv in s.values} for s in m.status if s.hardware_id == "foreign/agent_0"),
            queue_size=100)
        try:
            with robot_agent("/foreign", "_kinematics:=unicycle", "_robot_namespace:=/tb3_0") as (p, lines):
                wait_for_subscriber(self, pub, "the agent")
                for _ in range(10):
                    pub.publish(odometry("odom"))
                    time.sleep(0.2)
                time.sleep(6.0)  # a diagnostics update and a "holding" line after the last one
                self.assertIsNone(p.poll(), "the agent ended on odometry in another frame")
                said = [m.msg for m in lines]
                refused = [m for m in said if "refused odometry on /tb3_0/odom" in m]
                self.assertEqual(len(refused), 1, said)
                self.assertIn("in frame 'odom', not the world frame 'world'", refused[0])
                self.assertIn("the agent holds", refused[0])
                self.assertEqual(diagnostics[-1]["odometry refused (not in the world frame)"], "10", diagnostics[-1])
                # It holds: nothing was taken for a pose.
                self.assertFalse(any("first odometry" in m for m in said), said)
                self.assertTrue(any("no odometry on /tb3_0/odom yet (10 refused: not in the world frame 'world')" in m
                                    for m in said), said)
                # The world frame, written as tf1 did ("/world"), is taken.
                pub.publish(odometry("/world", 1.0, 2.0))
                end = time.time() + 10
                while not any("first odometry" in m.msg for m in lines) and time.time() < end:
                    time.sleep(0.1)
                self.assertTrue(any("first odometry on /tb3_0/odom" in m.msg for m in lines), [m.msg for m in lines])
        finally:
            sub.unregister()

    def test_odom_starts_refuses_another_frame(self):
        pubs = [rospy.Publisher(f"/starts/robot_{i}/odom", Odometry, queue_size=1, latch=True) for i in range(6)]
        for i, pub in enumerate(pubs):
            pub.publish(odometry("odom" if i == 0 else "world", float(i), 0.5))
        out = os.path.join(tempfile.mkdtemp(prefix="odom_starts_"), "starts.csv")
        command = ["rosrun", vf_rostest.PKG, "odom_starts.py", "--scenario", HEXAGON, "--ns", "/starts", "--out", out,
                   "--timeout", "4"]
        status, lines = run(command)
        self.assertEqual(status, 2, lines)
        self.assertEqual(len(lines), 2, lines)
        self.assertIn("warning: refused odometry on /starts/robot_0/odom in frame 'odom', not the world frame 'world'",
                      lines[0])
        self.assertIn("error: no odometry in the world frame 'world' on /starts/robot_0/odom within 4 s "
                      "(1 refused in frame 'odom')", lines[1])
        self.assertFalse(os.path.exists(out))
        pubs[0].publish(odometry("world", 0.0, 0.5))
        status, lines = run(command)
        self.assertEqual((status, lines), (0, []))
        with open(out) as f:
            self.assertEqual(f.read().splitlines(), ["agent,x,y,z"] + [f"{i},{float(i)!r},0.5,0.0" for i in range(6)])

    def monitor(self, name, **params):
        base = {"scenario": HEXAGON, "mode": "timed", "real_time_factor": "1", "measure_robots": "true"}
        base.update(params)
        return run(["rosrun", vf_rostest.PKG, "monitor", f"__name:={name}", "__ns:=/bad"] +
                   [f"_{k}:={v}" for k, v in base.items()])

    def test_monitor_refuses_bad_robot_settings(self):
        self.check(self.monitor("monitor_lockstep", mode="lockstep"), "measure_robots", "lockstep")
        self.check(self.monitor("monitor_tank", kinematics="tank"), "kinematics", "tank")
        self.check(self.monitor("monitor_hand", kinematics="unicycle", hand_offset="-0.1"), "hand_offset", "-0.1")
        self.check(self.monitor("monitor_window", robots_window="0"), "robots_window", "0")

    def monitor_sent(self, ns, messages, *params):
        """A timed monitor measuring robots in `ns`, without agents, sent `messages` on robot_0's
        odometry (the other robots never publish); its /rosout lines once it has run 6 s (its line
        about missing robots comes 5 s after the start). It must stay up."""
        lines = []
        sub = rospy.Subscriber("/rosout", Log, lambda m: lines.append(m.msg) if m.name == f"{ns}/monitor" else None,
                               queue_size=1000)
        pub = rospy.Publisher(f"{ns}/robot_0/odom", Odometry, queue_size=10)
        p = subprocess.Popen(["rosrun", vf_rostest.PKG, "monitor", "__name:=monitor", f"__ns:={ns}",
                              f"_scenario:={HEXAGON}", "_mode:=timed", "_real_time_factor:=1", "_measure_robots:=true"]
                             + list(params), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            wait_for_subscriber(self, pub, "the monitor")
            for m in messages:
                pub.publish(m)
                time.sleep(0.2)
            time.sleep(6.0)
            self.assertIsNone(p.poll(), "the monitor ended on the odometry sent")
        finally:
            p.send_signal(signal.SIGINT)
            p.wait(timeout=20)
            sub.unregister()
        return lines

    def test_monitor_drops_bad_odometry_and_names_the_robots_it_waits_for(self):
        # A timed monitor measuring unicycles; robot_0's odometry is not a pose.
        lines = self.monitor_sent("/watch", [odometry("world", x=float("nan"))], "_kinematics:=unicycle")
        dropped = [m for m in lines if "dropped an odometry message on /watch/robot_0/odom" in m]
        self.assertEqual(len(dropped), 1, lines)
        self.assertIn("robot_0: odometry:", dropped[0])
        self.assertIn("1 dropped so far", dropped[0])
        waiting = [m for m in lines if "waiting for the robots' odometry" in m]
        self.assertTrue(waiting, lines)
        self.assertIn("no odometry yet on " + ", ".join(f"/watch/robot_{i}/odom" for i in range(6)), waiting[0])

    def test_monitor_refuses_odometry_in_another_frame(self):
        lines = self.monitor_sent("/frames", [odometry("odom")] * 3)
        refused = [m for m in lines if "refused odometry" in m]
        self.assertEqual(len(refused), 1, lines)
        self.assertIn("on /frames/robot_0/odom in frame 'odom', not the world frame 'world'", refused[0])
        # robot_0 is not measured: still among those it waits for, with the count.
        waiting = [m for m in lines if "waiting for the robots' odometry" in m]
        self.assertTrue(waiting, lines)
        self.assertIn("no odometry yet on /frames/robot_0/odom, /frames/robot_1/odom", waiting[0])
        self.assertIn("(3 refused: not in the world frame 'world')", waiting[0])

    def test_missing_odometry_holds_and_says_so(self):
        # A robot-mode agent whose odom topic has no publisher: it stays up, holds, and says so
        # every few seconds (no monitor either: it would not start anyway).
        with robot_agent("/lonely", "_robot_namespace:=/nobody") as (p, lines):
            said = lambda: [m for m in list(lines) if "no odometry on /nobody/odom" in m.msg]  # noqa: E731
            self.assertTrue(vf_rostest.wait_until(lambda: len(said()) >= 3, 30.0),
                            f"{len(said())} lines in 30 s: {[m.msg for m in lines]}")
            self.assertIsNone(p.poll(), "the agent ended without odometry")
        # Said every 5 s (ROS_WARN_THROTTLE), by the stamps of its lines: not once per tick.
        stamps = [m.header.stamp.to_sec() for m in said()]
        gaps = [b - a for a, b in zip(stamps, stamps[1:])]
        self.assertTrue(all(4.5 <= g <= 7.5 for g in gaps[:2]), f"seconds between the lines: {gaps}")


if __name__ == "__main__":
    rostest.rosrun(vf_rostest.PKG, "timed_bad_input", TimedBadInput)
