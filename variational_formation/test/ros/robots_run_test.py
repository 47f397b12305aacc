#!/usr/bin/python3
"""rostest (robots_run.test): simulated robots (1 cm odometry noise) driven by time-driven agents in
robot mode form the shape, checked from the robots' own odometry in the recorded bag, not from the
agents' states.

- The run succeeds and the monitor says the formation converged.
- The monitor measured the robots from their odometry (robot mode): the result file carries the
  robots' figures, the run converged at the later of the agents' and the robots' steps, the
  robots' max distance error at the end is within the tolerance, and it agrees (3 mm) with this
  test's own average of the recorded odometry; every status from the robots' step on says in shape.
- The robots' points (a unicycle's hand point, hand_offset ahead of the axle at the odometry
  heading), averaged over the run's last second, are congruent with the desired shape: every
  pair's distance within 1 cm of the desired one.
- The bag holds every robot's odometry and cmd_vel throughout (recording in timed mode).
- Every stamp in the bag (headers, tf and markers) is within 1 s of the time it was recorded at:
  robots' topics are in ROS time. The first message of a topic may be a latched one, published
  before rosbag subscribed: it may be older, but by less than 30 s (not from 1970).
- Frames: every stamped message and transform is in the world frame (the case's world_frame),
  and a robot's frame is formation/robot_<i>/base_link (its namespace once).
- Unicycles: every cmd_vel has linear.y = linear.z = 0, and every robot really turned. Holonomic
  robots: no cmd_vel turns, and base_link keeps the world's axes.
- Every agent compares its robot's lag plus one tick with the scenario's delay margin and reports
  both numbers in its diagnostics; the case says whether the lag exceeds the margin (ring7's
  margin is 0.05 s, the hexagon's wider than 0.114 s). In the MuJoCo world the lag is the one
  world_step_response measures.
- Both worlds add `contacts: 0` and `first_contact: ~` to the result file (robot_sim's robot 0,
  or the MuJoCo world): no two robot bodies ever touch. The MuJoCo world's robots publish
  joint_states.
- A scenario with `safety:` (the scattered unicycles): the filter bound (filter_active_steps > 0
  in the result file, constraints_active > 0 in some status), and the closest approach of the
  agents' points is at least r + 2 hand_offset minus what stale data can cost (checked loosely:
  >= r).
"""
import math
import os
import shutil
import subprocess
import sys
import time
import unittest

import rosbag
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from variational_formation_msgs.msg import FormationStatus

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402

TOLERANCE = 0.01  # [m] on every pair distance, from the robots' averaged odometry
STAMP_TOLERANCE = 1.0  # [s] between a stamp and the time the bag received it
LATCHED_AGE = 30.0  # [s] a topic's first message may be this much older (latched before rosbag came)


def yaw(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def wrapped(angle):
    return math.atan2(math.sin(angle), math.cos(angle))


@vf_rostest.reported_setup
class RobotsRun(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("robots_run_test")
        cls.diagnostics = {}  # hardware id -> the newest status's values
        cls.diagnostics_sub = rospy.Subscriber("/diagnostics", DiagnosticArray, cls.on_diagnostics, queue_size=100)
        cls.path = rospy.get_param("~scenario")
        cls.out = rospy.get_param("~output_dir")
        cls.kinematics = rospy.get_param("~kinematics")
        cls.world = rospy.get_param("~world", "kinematic")
        cls.hand_offset = float(rospy.get_param("~hand_offset"))
        cls.lag = float(rospy.get_param("~lag"))
        cls.expect_lag_warning = rospy.get_param("~expect_lag_warning")
        cls.world_frame = rospy.get_param("~world_frame")
        # "vx_vy": a velocity command 2 s into the run and a stop 6.5 s later (empty: none).
        cls.command = [float(x) for x in str(rospy.get_param("~command", "")).replace("_", " ").split()]
        cls.frames = set()  # (parent, child) of every transform; (frame, topic) of every other header
        cls.scenario = vf_rostest.load_scenario(cls.path)
        name = os.path.basename(cls.path).replace(".yaml", "")
        steps, h = cls.scenario["steps"], cls.scenario["time_step"]
        if cls.command:
            steering = vf_rostest.Steering("/formation", cls.scenario["n"])
            status = []
            sub = rospy.Subscriber("/formation/status", FormationStatus, lambda m: status.append(m.step), queue_size=100)
            while not status or status[-1] < 140:
                time.sleep(0.01)
            steering.send(*cls.command)
            cls.sent_at = rospy.Time.now().to_sec()
            while status[-1] < 600:
                time.sleep(0.01)
            steering.send(0.0, 0.0)
            cls.stopped_at = rospy.Time.now().to_sec()
            sub.unregister()
            steering.close()
        result_file = os.path.join(cls.out, name + ".result.yaml")
        cls.result = vf_rostest.wait_for_result(result_file, steps * h + 30.0)
        # The world (robot_sim's robot 0, or mujoco_world) adds its contacts once the monitor has written the file.
        end = time.time() + 10
        while "contacts" not in cls.result and time.time() < end:
            time.sleep(0.2)
            cls.result = vf_rostest.wait_for_result(result_file, 0)
        # Stop the recorder (rosnode kill: a clean shutdown) so that the bag is closed and indexed.
        subprocess.run(["rosnode", "kill", "/formation/recorder"], capture_output=True)
        bag = os.path.join(cls.out, name + ".bag")
        end = time.time() + 15
        while not os.path.exists(bag) and time.time() < end:
            time.sleep(0.2)
        cls.odom, cls.cmd_vel, cls.status, cls.joint_states = {}, {}, [], {}
        cls.stamps = 0
        cls.worst_stamp = (0.0, "")
        cls.worst_first = (0.0, "")
        cls.seen = set()
        with rosbag.Bag(bag) as b:
            for topic, msg, t in b.read_messages():
                cls.check_stamps(topic, msg, t)
                if topic.endswith("/odom"):
                    cls.odom.setdefault(topic, []).append((t.to_sec(), msg))
                elif topic.endswith("/cmd_vel") and "/robot_" in topic:  # not the formation's formation/cmd_vel
                    cls.cmd_vel.setdefault(topic, []).append(msg)
                elif topic.endswith("/joint_states"):
                    cls.joint_states[topic] = cls.joint_states.get(topic, 0) + 1
                elif topic == "/formation/status":
                    cls.status.append((t.to_sec(), msg))

    @classmethod
    def on_diagnostics(cls, msg):
        for s in msg.status:
            if s.hardware_id.startswith("formation/agent_"):
                cls.diagnostics[s.hardware_id] = {kv.key: kv.value for kv in s.values}

    @classmethod
    def check_stamps(cls, topic, msg, t):
        headers = [msg.header] if hasattr(msg, "header") else []
        headers += [tf.header for tf in getattr(msg, "transforms", [])]
        headers += [m.header for m in getattr(msg, "markers", [])]
        for tf in getattr(msg, "transforms", []):
            cls.frames.add((tf.header.frame_id, tf.child_frame_id))
        for header in ([msg.header] if hasattr(msg, "header") else []) + [m.header for m in getattr(msg, "markers", [])]:
            if header.frame_id:
                cls.frames.add((header.frame_id, topic.rsplit("/", 1)[-1]))
        first = topic not in cls.seen
        cls.seen.add(topic)
        for header in headers:
            cls.stamps += 1
            late = (t - header.stamp).to_sec()  # > 0: the stamp is older than the record time
            if first and 0.0 <= late < LATCHED_AGE:
                cls.worst_first = max(cls.worst_first, (late, topic))
                continue
            if abs(late) > cls.worst_stamp[0]:
                cls.worst_stamp = (abs(late), topic)

    @classmethod
    def tearDownClass(cls):
        cls.diagnostics_sub.unregister()
        shutil.rmtree(cls.out, ignore_errors=True)

    def n(self):
        return self.scenario["n"]

    def test_run_ends_converged(self):
        self.assertEqual(self.result.get("result"), "succeeded", f"result file: {self.result}")
        self.assertGreaterEqual(int(self.result.get("converged_step", -1)), 0, f"result file: {self.result}")

    def test_bag_holds_every_robots_odometry_and_commands(self):
        n = self.n()
        self.assertEqual(sorted(self.odom), sorted(f"/formation/robot_{i}/odom" for i in range(n)))
        self.assertEqual(sorted(self.cmd_vel), sorted(f"/formation/robot_{i}/cmd_vel" for i in range(n)))
        for topic, msgs in self.odom.items():
            span = msgs[-1][0] - msgs[0][0]
            self.assertGreater(span, 0.5 * self.scenario["steps"] * self.scenario["time_step"], topic)
            self.assertGreater(len(msgs), 50 * span, f"{topic}: {len(msgs)} messages in {span:.1f} s")  # 100 Hz

    def test_stamps_are_ros_time(self):
        print(f"stamps: {self.stamps} checked, worst {self.worst_stamp[0]:.3f} s from its record time "
              f"({self.worst_stamp[1]}); first (latched) messages up to {self.worst_first[0]:.3f} s older "
              f"({self.worst_first[1]})", flush=True)
        self.assertGreater(self.stamps, 1000)
        self.assertLess(self.worst_stamp[0], STAMP_TOLERANCE, self.worst_stamp[1])

    def point(self, msg):
        """The robot's controlled point from an odometry message: the hand point of a unicycle."""
        p = msg.pose.pose.position
        if self.kinematics != "unicycle":
            return p.x, p.y
        theta = yaw(msg.pose.pose.orientation)
        return p.x + self.hand_offset * math.cos(theta), p.y + self.hand_offset * math.sin(theta)

    def mean_points(self, t0, t1):
        """Each robot's point averaged over its odometry recorded in [t0, t1)."""
        mean = []
        for i in range(self.n()):
            window = [self.point(m) for t, m in self.odom[f"/formation/robot_{i}/odom"] if t0 <= t < t1]
            self.assertTrue(window, f"robot_{i}: no odometry in [{t0:.1f}, {t1:.1f})")
            mean.append((sum(p[0] for p in window) / len(window), sum(p[1] for p in window) / len(window)))
        return mean

    def desired(self):
        return [a["desired_position"] for a in sorted(self.scenario["agents"], key=lambda a: a["id"])]

    def pair_error(self, t0, t1):
        """Worst | |p_i - p_j| - |q*_i - q*_j| | [m] over all pairs, points averaged over [t0, t1)."""
        mean, desired = self.mean_points(t0, t1), self.desired()
        return max(abs(math.dist(mean[a], mean[b]) - math.dist(desired[a], desired[b]))
                   for a in range(self.n()) for b in range(a + 1, self.n()))

    def test_verdict_is_the_robots_from_their_odometry(self):
        # The monitor measured the robots (robots.launch sets ~measure_robots): the result file has
        # their figures, the run converged at the later of the agents' and the robots' steps, and
        # what it says of the robots at the end is what this test measures in the recorded odometry.
        r = self.result
        for key in ("robots_in_shape_step", "robots_max_distance_error", "robots_shape_error", "agents_converged_step",
                    "odometry_dropped", "robots"):
            self.assertIn(key, r)
        robots, agents = int(r["robots_in_shape_step"]), int(r["agents_converged_step"])
        print(f"monitor: agents converged at step {agents}, robots in shape from step {robots}, run converged at "
              f"step {r['converged_step']}; robots at the end: max distance error {r['robots_max_distance_error']:.4f} m, "
              f"shape error {r['robots_shape_error']:.4f} m ({r['robots']})", flush=True)
        self.assertGreaterEqual(robots, 0, r)
        self.assertEqual(int(r["converged_step"]), max(robots, agents), r)
        self.assertEqual(r["odometry_dropped"], 0)
        self.assertEqual(r["odometry_refused_frame"], 0)  # the robots' odometry is in the world frame
        desired = self.desired()
        # In shape: every pair within 1% of its desired distance, so every edge within 1% of the longest.
        longest = max(math.dist(desired[a], desired[b]) for a, b in self.scenario["edges"])
        self.assertLess(r["robots_max_distance_error"], 0.01 * longest, r)
        # The statuses say the same: the last one carries the result's figures, and every status
        # from the robots' step on has the robots in shape.
        end, last = self.status[-1]
        self.assertEqual(last.robots_in_shape_step, robots)
        self.assertAlmostEqual(last.robots_max_distance_error, r["robots_max_distance_error"], delta=1e-5)
        in_stretch = [s.robots_in_shape for _, s in self.status if s.step >= robots]
        self.assertTrue(in_stretch and all(in_stretch), f"{in_stretch.count(False)} of {len(in_stretch)} not in shape")
        # This test's own measurement: the recorded odometry over the monitor's window (0.5 s)
        # before its last status. The two averages hold nearly the same samples.
        mean = self.mean_points(end - 0.5, end)
        own = max(abs(math.dist(mean[a], mean[b]) - math.dist(desired[a], desired[b])) for a, b in self.scenario["edges"])
        slack = max(abs(math.dist(mean[a], mean[b]) - math.dist(desired[a], desired[b])) - 0.01 * math.dist(desired[a], desired[b])
                    for a in range(self.n()) for b in range(a + 1, self.n()))
        print(f"test: the robots' max distance error from the bag's odometry {own:.4f} m (monitor "
              f"{r['robots_max_distance_error']:.4f} m); worst pair {slack * 1000:+.2f} mm beyond 1%", flush=True)
        self.assertLess(abs(own - r["robots_max_distance_error"]), 0.003)
        self.assertLess(slack, 0.003)

    def test_robots_form_the_shape(self):
        self.assertTrue(self.status, "no status in the bag")
        # From when the bag has every robot (rosbag subscribes to each odom as it finds it).
        start = max(msgs[0][0] for msgs in self.odom.values())
        end = self.status[-1][0]  # the monitor's last status: the end of the run
        profile = [self.pair_error(t, t + 1.0) for t in range(int(start), int(end) - 1)]
        print("robots: worst pair distance error per second [m]: " + " ".join(f"{e:.3f}" for e in profile),
              flush=True)
        formed = next((k for k in range(len(profile)) if all(e < TOLERANCE for e in profile[k:])), None)
        worst = self.pair_error(end - 1.0, end)
        print(f"robots ({self.kinematics}, {self.world} world, lag {self.lag} s): worst pair distance error {worst * 1000:.2f} mm over "
              f"the run's last second; within {TOLERANCE * 100:.0f} cm from second "
              f"{formed if formed is not None else 'never'} of the run", flush=True)
        self.assertLess(worst, TOLERANCE)

    def test_frames(self):
        parents = {parent for parent, _ in self.frames}
        self.assertEqual(parents, {self.world_frame}, sorted(self.frames))
        children = {child for _, child in self.frames}
        for i in range(self.n()):
            self.assertIn(f"formation/robot_{i}/base_link", children)
            self.assertIn(f"formation/agent_{i}", children)
        for topic, msgs in self.odom.items():
            self.assertEqual({m.child_frame_id for _, m in msgs}, {topic.replace("/odom", "/base_link")[1:]})

    def test_robots_follow_a_commanded_velocity(self):
        if not self.command:
            self.assertFalse(hasattr(self, "sent_at"))  # nothing was sent
            return
        # The robots' centroid (hand points), from the odometry averaged over 0.5 s before the
        # command and 2 s after the stop (the coast of 1/kappa and the robots' lag are over).
        def centroid(t0, t1):
            points = []
            for i in range(self.n()):
                window = [self.point(m) for t, m in self.odom[f"/formation/robot_{i}/odom"] if t0 <= t < t1]
                points.append([sum(p[c] for p in window) / len(window) for c in range(2)])
            return [sum(p[c] for p in points) / self.n() for c in range(2)]
        before = centroid(self.sent_at - 0.5, self.sent_at)
        after = centroid(self.stopped_at + 2.0, self.stopped_at + 2.5)
        seconds = self.stopped_at - self.sent_at
        moved = [b - a for a, b in zip(before, after)]
        wanted = [v * seconds for v in self.command]
        error = math.dist(moved, wanted)
        print(f"robots ({self.kinematics}): commanded {self.command} m/s for {seconds:.2f} s: moved "
              f"{[round(x, 3) for x in moved]} m, wanted {[round(x, 3) for x in wanted]} m "
              f"({100 * error / math.hypot(*wanted):.1f}% off)", flush=True)
        self.assertLess(error, 0.1 * math.hypot(*wanted))

    def test_commands_suit_the_kinematics(self):
        msgs = [m for v in self.cmd_vel.values() for m in v]
        self.assertTrue(msgs)
        if self.kinematics == "unicycle":
            self.assertEqual(max(abs(m.linear.y) + abs(m.linear.z) for m in msgs), 0.0)
            self.assertGreater(max(abs(m.angular.z) for m in msgs), 0.0)
        else:
            self.assertEqual(max(abs(m.angular.x) + abs(m.angular.y) + abs(m.angular.z) for m in msgs), 0.0)

    def test_unicycles_really_turned(self):
        if self.kinematics != "unicycle":
            # A point robot's base_link keeps the world's axes; a MuJoCo base's yaw is held by a
            # servo at the commanded rate 0.
            yaws = {yaw(m.pose.pose.orientation) for v in self.odom.values() for _, m in v}
            if self.world == "mujoco":
                self.assertLess(max(abs(y) for y in yaws), 1e-3)
            else:
                self.assertEqual(yaws, {0.0})
            return
        for i in range(self.n()):
            headings = [yaw(m.pose.pose.orientation) for _, m in self.odom[f"/formation/robot_{i}/odom"]]
            turned = max(abs(wrapped(h - headings[0])) for h in headings)
            print(f"robot_{i}: heading {headings[0]:+.3f} rad at start, turned up to {turned:.3f} rad", flush=True)
            self.assertGreater(turned, 0.1, f"robot_{i} did not turn")

    def test_agents_compare_the_lag_with_the_delay_margin(self):
        agents = {f"formation/agent_{i}" for i in range(self.n())}
        self.assertEqual(set(self.diagnostics), agents, "every agent's diagnostics")
        tick = self.scenario["time_step"]  # rate 1
        lag = self.lag
        if self.world == "mujoco":
            response = subprocess.run(["rosrun", "variational_formation", "world_step_response", "--kinematics",
                                       self.kinematics], capture_output=True, text=True, check=True)
            lag = float(response.stdout.split()[1])
            print(f"MuJoCo world ({self.kinematics}): step response lag {lag:.4f} s", flush=True)
        for agent, values in sorted(self.diagnostics.items()):
            lag_plus_tick = float(values["robot lag + tick [s]"])
            margin = float(values["delay margin [s]"])
            exceeds = values["lag exceeds the delay margin"] == "True"
            print(f"{agent}: robot lag + tick {lag_plus_tick:.3f} s, delay margin {margin:.3f} s, exceeded {exceeds}",
                  flush=True)
            # The diagnostics give 6 digits: the kinematic lags are that short, the measured one is not.
            self.assertAlmostEqual(lag_plus_tick, lag + tick, places=9 if self.world == "kinematic" else 6)
            self.assertEqual(exceeds, margin >= 0 and lag_plus_tick > margin, values)
            self.assertEqual(exceeds, self.expect_lag_warning, values)

    def test_world_reports_its_contacts(self):
        print(f"{self.world} world: contacts {self.result.get('contacts')}, first {self.result.get('first_contact')}",
              flush=True)
        self.assertEqual(self.result.get("contacts"), 0, self.result)
        self.assertIn("first_contact", self.result)
        self.assertIsNone(self.result["first_contact"])
        if self.world == "mujoco":
            self.assertEqual(sorted(self.joint_states),
                             sorted(f"/formation/robot_{i}/joint_states" for i in range(self.n())))

    def test_safety_filter_bound(self):
        safety = self.scenario.get("safety")
        if not safety:
            self.assertNotIn("filter_active_steps", self.result)
            return
        closest = self.result.get("closest_approach")
        print(f"safety: filter active in {self.result.get('filter_active_steps')} steps, closest approach {closest}, "
              f"statuses with constraints active: {sum(1 for _, s in self.status if s.constraints_active > 0)}",
              flush=True)
        self.assertGreater(int(self.result.get("filter_active_steps", 0)), 0, self.result)
        self.assertTrue(any(s.constraints_active > 0 for _, s in self.status))
        self.assertGreaterEqual(closest["distance"], safety["radius"], self.result)


if __name__ == "__main__":
    rostest.rosrun(vf_rostest.PKG, "robots_run", RobotsRun)
