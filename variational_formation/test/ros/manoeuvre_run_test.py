#!/usr/bin/python3
"""rostest (manoeuvre_run.test): live commands in a recorded lockstep run.

This node, a real foreign node, sends Twist commands on formation/cmd_vel and scale commands on
formation/scale at wall times drawn from its seed (printed), while hexagon_manoeuvre runs its own
schedule. Then:

- the run succeeds, and the result file counts the issued commands;
- `simulate --commands` on the recorder's <name>.commands.csv equals every recorded state bit for
  bit, each (agent, step) once;
- the bag's formation/command messages hold the issued commands, each written at the step it
  applies from;
- without faults: bad commands (NaN, scale 0, a z velocity in 2D, and a good one from a node not
  in ~commanders: a `rostopic pub` of its own) are dropped and counted, and the run goes on; a
  command of 1000 m/s is kept at the monitor's ~max_speed (2 m/s) and counted as saturated;
- with faults: an agent and then the monitor are killed (SIGKILL) during the manoeuvre, after
  some commands and before others; they respawn and the run stays exact.
"""
import math
import os
import random
import shutil
import signal
import subprocess
import sys
import time
import unittest

import rosbag
import rospy
import rostest
import yaml
from geometry_msgs.msg import Twist
from std_msgs.msg import Float64

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402
from variational_formation_msgs.msg import FormationStatus  # noqa: E402

NS = "/formation"
COMMANDS = 6


@vf_rostest.reported_setup
class ManoeuvreRun(unittest.TestCase, vf_rostest.RunChecks):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("manoeuvre_run_test")
        cls.seed = int(rospy.get_param("~seed"))
        cls.faults = bool(rospy.get_param("~faults"))
        cls.out = rospy.get_param("~output_dir")
        rate = float(rospy.get_param("~rate"))
        cls.path = vf_rostest.scenario_path("hexagon_manoeuvre")
        cls.scenario = vf_rostest.load_scenario(cls.path)
        steps, h = int(cls.scenario["steps"]), float(cls.scenario["time_step"])
        print(f"manoeuvre_run_test: seed {cls.seed}, faults {cls.faults}", flush=True)
        rng = random.Random(cls.seed)
        cls.step = -1
        status = rospy.Subscriber(f"{NS}/status", FormationStatus, cls.on_status, queue_size=100)
        velocity = rospy.Publisher(f"{NS}/cmd_vel", Twist, queue_size=10, latch=False)
        scale = rospy.Publisher(f"{NS}/scale", Float64, queue_size=10, latch=False)
        end = time.time() + 60
        while (velocity.get_num_connections() == 0 or scale.get_num_connections() == 0) and time.time() < end:
            time.sleep(0.1)
        assert velocity.get_num_connections() and scale.get_num_connections(), "the monitor never subscribed"
        # Commands at steps drawn over the first 70% of the run (wall time: step h / rate).
        at = sorted(rng.sample(range(50, int(0.7 * steps)), COMMANDS))
        cls.sent, cls.bad_sent, cls.saturated_sent, cls.kills, cls.intruder = [], 0, 0, [], None
        kill_agent_after, kill_monitor_after = 2, 4  # commands sent before each kill (faults)
        for n, step in enumerate(at):
            cls.wait_for_step(step, steps * h / rate + 60)
            if n % 2 == 0:
                t = Twist()
                t.linear.x, t.linear.y = rng.uniform(-0.6, 0.6), rng.uniform(-0.6, 0.6)
                t.angular.z = rng.uniform(-0.4, 0.4)
                velocity.publish(t)
                cls.sent.append(("cmd_vel", step, (t.linear.x, t.linear.y, t.angular.z)))
            else:
                s = rng.uniform(0.8, 1.4)
                scale.publish(Float64(s))
                cls.sent.append(("scale", step, s))
            if not cls.faults and n == 1:
                cls.send_bad(velocity, scale)
            if cls.faults and n + 1 in (kill_agent_after, kill_monitor_after):
                victim = f"{NS}/agent_{rng.randrange(cls.scenario['n'])}" if n + 1 == kill_agent_after else f"{NS}/monitor"
                time.sleep(rng.uniform(0.05, 0.5))
                os.kill(vf_rostest.node_pid(victim), signal.SIGKILL)
                cls.kills.append((victim, cls.step))
                print(f"manoeuvre_run_test: SIGKILL to {victim} at step {cls.step}", flush=True)
                time.sleep(0.5)
                vf_rostest.node_pid(victim, timeout=30.0)  # respawned
        print(f"manoeuvre_run_test: sent {cls.sent}", flush=True)
        if cls.intruder is not None:
            cls.intruder.wait(timeout=60)
        status.unregister()
        name = "hexagon_manoeuvre"
        cls.result = vf_rostest.wait_for_result(os.path.join(cls.out, name + ".result.yaml"), steps * h / rate + 90)
        cls.commands_file = os.path.join(cls.out, name + ".commands.csv")
        cls.expected = vf_rostest.simulate(cls.path, cls.commands_file) if os.path.exists(cls.commands_file) else {}
        cls.bag = os.path.join(cls.out, name + ".bag")

    @classmethod
    def on_status(cls, msg):
        cls.step = max(cls.step, msg.step)

    @classmethod
    def wait_for_step(cls, step, timeout):
        end = time.time() + timeout
        while cls.step < step and time.time() < end:
            time.sleep(0.005)
        assert cls.step >= step, f"the run never reached step {step} (newest status: {cls.step})"

    @classmethod
    def send_bad(cls, velocity, scale):
        nan = Twist()
        nan.linear.x = float("nan")
        velocity.publish(nan)
        scale.publish(Float64(0.0))
        up = Twist()
        up.linear.z = 0.3  # a 2D formation has no z velocity
        velocity.publish(up)
        # Beyond the formation's ~max_speed (2 m/s): saturated, kept and counted.
        fast = Twist()
        fast.linear.x = 1000.0
        velocity.publish(fast)
        cls.saturated_sent = 1
        # A good command from a node that is not in ~commanders. Its rostopic pub takes seconds
        # (start-up, and 3 s latched after publishing): in the background, so that the commands
        # after it still go out at their steps.
        cls.intruder = subprocess.Popen(["rostopic", "pub", "-1", f"{NS}/cmd_vel", "geometry_msgs/Twist",
                                         "{linear: {x: 0.1, y: 0.0, z: 0.0}}", "__name:=intruder"],
                                        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        cls.bad_sent = 4

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.out, ignore_errors=True)

    def test_run_succeeds_and_counts_the_commands(self):
        self.assertEqual(self.result.get("result"), "succeeded", f"result file: {self.result}")
        # Each input makes one command, unless two came before the allowed step moved (merged).
        self.assertGreaterEqual(int(self.result["commands"]), 2)
        self.assertLessEqual(int(self.result["commands"]), COMMANDS + self.saturated_sent)
        self.assertEqual(int(self.result["commands_refused"]), self.bad_sent, f"result file: {self.result}")
        self.assertEqual(int(self.result["commands_saturated"]), self.saturated_sent, f"result file: {self.result}")
        # No command beyond ~max_speed reached the agents: the 1000 m/s input ran at 2 m/s at most
        # (a later velocity before the allowed step moved would replace it).
        with open(self.commands_file) as f:
            speeds = [math.hypot(float(r.split(",")[1]), float(r.split(",")[2])) for r in list(f)[1:]]
        self.assertLessEqual(max(speeds), 2.0 + 1e-12, speeds)

    def test_bag_equals_simulate_on_the_commands_file(self):
        self.assertTrue(self.expected, f"no commands file {self.commands_file}")
        rec = vf_rostest.Recording(self.bag)
        n, steps = self.scenario["n"], int(self.scenario["steps"])
        self.check_each_step_once(rec, n, steps)
        differ = [(i, k) for (i, k), msgs in rec.states.items() for m in msgs if list(m.position) != self.expected[(i, k)]]
        self.assertEqual(differ[:5], [], f"{len(differ)} recorded states differ from simulate --commands")
        self.check_no_noether_prediction(rec)

    def test_commands_file_and_bag_hold_the_issued_commands(self):
        with open(self.commands_file) as f:
            rows = [line.strip().split(",") for line in f][1:]
        schedule = self.scenario["manoeuvre"]
        self.assertGreater(len(rows), len(schedule) - 1, rows)
        rec = vf_rostest.Recording(self.bag)
        self.assertTrue(rec.commands, "no formation/command in the bag")
        h = float(self.scenario["time_step"])
        issued = rec.commands[-1][1].commands
        self.assertEqual(len(issued), int(self.result["commands"]))
        for t, msg in rec.commands:
            # Written at the step the newest of its commands applies from.
            self.assertAlmostEqual(t, msg.commands[-1].step * h, delta=1e-6)
        # Every issued command is a row of the file, from its step on (later ones may replace it).
        steps = {int(r[0]) for r in rows}
        self.assertTrue({c.step for c in issued} <= steps, (sorted(steps), [c.step for c in issued]))
        for c in issued:
            row = next(r for r in rows if int(r[0]) == c.step)
            self.assertEqual([float(x) for x in row[1:]], [c.velocity.x, c.velocity.y, c.velocity.z, c.angular_rate.x,
                                                            c.angular_rate.y, c.angular_rate.z, c.scale])

    def test_markers_show_the_command(self):
        # The last step's markers: an arrow of v* from the centroid, and the ghost of the desired
        # shape scaled by s (the file's last row governs the last step).
        with open(self.commands_file) as f:
            last = [float(x) for x in list(f)[-1].strip().split(",")]
        velocity, s = last[1:4], last[7]
        steps = int(self.scenario["steps"])
        markers = None
        with rosbag.Bag(self.bag) as bag:
            for _, msg, t in bag.read_messages(topics=[f"{NS}/markers"]):
                markers = msg  # the last one is the last step's
        self.assertIsNotNone(markers, "no markers in the bag")
        by_ns = {(m.ns, m.id): m for m in markers.markers}
        rec = vf_rostest.Recording(self.bag)
        n = self.scenario["n"]
        centroid = [sum(rec.states[(i, steps)][0].position[c] for i in range(n)) / n for c in range(2)]
        arrow = by_ns.get(("command", 0))
        self.assertIsNotNone(arrow, sorted(by_ns))
        if any(velocity):
            self.assertEqual(arrow.type, arrow.ARROW)
            self.assertAlmostEqual(arrow.points[0].x, centroid[0], delta=1e-9)
            self.assertAlmostEqual(arrow.points[0].y, centroid[1], delta=1e-9)
            self.assertAlmostEqual(arrow.points[1].x - arrow.points[0].x, velocity[0], delta=1e-9)
            self.assertAlmostEqual(arrow.points[1].y - arrow.points[0].y, velocity[1], delta=1e-9)
        else:
            self.assertEqual(arrow.action, arrow.DELETE)
        # Edges coloured by their error against s d_ij: the formation holds the scaled shape.
        self.assertLess(max(c.r for c in by_ns[("edges", 0)].colors), 0.1)
        ghost = by_ns[("desired_shape", 0)].points
        desired = {a["id"]: a["desired_position"] for a in self.scenario["agents"]}
        for e, (a, b) in enumerate(self.scenario["edges"]):
            length = math.dist((ghost[2 * e].x, ghost[2 * e].y), (ghost[2 * e + 1].x, ghost[2 * e + 1].y))
            self.assertAlmostEqual(length / (s * math.dist(desired[a], desired[b])), 1.0, delta=1e-9)

    def test_faults_were_injected(self):
        if self.faults:
            self.assertEqual([v for v, _ in self.kills][1], f"{NS}/monitor")
            self.assertEqual(len(self.kills), 2)
        else:
            self.assertEqual(self.kills, [])


if __name__ == "__main__":
    rostest.rosrun(vf_rostest.PKG, "manoeuvre_run", ManoeuvreRun)
