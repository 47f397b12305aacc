#!/usr/bin/python3
"""rostest (goal.test): goals for a recorded lockstep formation, sent as a user would.

In one run of goal_hexagon (hexagon_steer, side 2, for 45 s of simulated time at rate 5):
1. an action goal on formation/move_to (move_base_msgs/MoveBase) succeeds, with feedback, and
   the centroid (computed here from the agents' own states) and the heading (a 2D Kabsch fit of
   the desired shape, computed here) end within the tolerances (5 cm, 0.05 rad) plus what the
   formation drifts after the stop;
2. a far action goal is pre-empted by a PoseStamped on /move_base_simple/goal (rviz's 2D Nav
   Goal), and the formation comes to rest there;
3. an action goal cancelled on the way ends PREEMPTED, and the formation stops;
4. goals with a zero quaternion or in another frame are aborted, saying why.
Then the run succeeds in the desired shape, and `simulate --commands` on the recorder's
goal_hexagon.commands.csv equals every recorded state bit for bit: the goals' commands were
step-stamped like any other.
"""
import math
import os
import sys
import time
import unittest

import actionlib
import rospy
import rostest
from actionlib_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseStamped
from move_base_msgs.msg import MoveBaseAction, MoveBaseActionResult, MoveBaseGoal

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402
from variational_formation_msgs.msg import FormationStatus  # noqa: E402

NS = "/formation"


pose = vf_rostest.goal_pose
wrap = vf_rostest.wrap


@vf_rostest.reported_setup
class GoalRun(unittest.TestCase, vf_rostest.RunChecks):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("goal_test")
        cls.out = rospy.get_param("~output_dir")
        cls.path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "goal_hexagon.yaml")
        cls.scenario = vf_rostest.load_scenario(cls.path)
        steps, h = int(cls.scenario["steps"]), float(cls.scenario["time_step"])
        cls.step, cls.feedback = -1, []
        cls.log = vf_rostest.AgentStates(NS, cls.scenario)
        subs = [rospy.Subscriber(f"{NS}/status", FormationStatus, cls.on_status, queue_size=100)]
        cls.results = []  # every goal's end, the topic's too: (goal id, status)
        subs.append(rospy.Subscriber(f"{NS}/move_to/result", MoveBaseActionResult,
                                     lambda m: cls.results.append((m.status.goal_id.id, m.status.status)), queue_size=10))
        cls.topic = rospy.Publisher("/move_base_simple/goal", PoseStamped, queue_size=1)
        cls.client = actionlib.SimpleActionClient(f"{NS}/move_to", MoveBaseAction)
        cls.wait(lambda: cls.step >= 100, 60, "the run to form (step 100)")
        cls.client.wait_for_server()
        cls.wait(lambda: cls.topic.get_num_connections() > 0, 20, "the monitor to take /move_base_simple/goal")

        # 1. An action goal: reached.
        cls.goal1 = (2.0, 1.0, 0.6)
        cls.client.send_goal(MoveBaseGoal(target_pose=pose(*cls.goal1)), feedback_cb=cls.feedback.append)
        cls.wait(lambda: cls.client.get_state() not in (GoalStatus.PENDING, GoalStatus.ACTIVE), 60, "goal 1")
        cls.state1, cls.text1 = cls.client.get_state(), cls.client.get_goal_status_text()
        cls.pose1 = cls.rest(2.0)

        # 2. A far action goal (6 m, 12 s at 0.5 m/s: one the run could still reach), pre-empted by
        # rviz's topic.
        cls.client.send_goal(MoveBaseGoal(target_pose=pose(8.0, 0.0, 0.0)))
        cls.wait_steps(100)
        cls.goal3 = (1.0, -1.0, -0.4)
        cls.topic.publish(pose(*cls.goal3))
        cls.wait(lambda: cls.client.get_state() != GoalStatus.ACTIVE, 20, "goal 2 to end")
        cls.state2 = cls.client.get_state()
        ended = len(cls.results)
        cls.wait(lambda: any(st == GoalStatus.SUCCEEDED for _, st in cls.results[ended:]), 60, "the topic's goal")
        cls.pose3 = cls.rest(2.0)

        # 3. Cancelled on the way.
        cls.client.send_goal(MoveBaseGoal(target_pose=pose(-2.0, 0.0, 1.0)))  # 3.2 m: 6.3 s, within what is left
        cls.wait_steps(150)
        cls.client.cancel_goal()
        cls.wait(lambda: cls.client.get_state() != GoalStatus.ACTIVE, 20, "goal 4 to end")
        cls.state4 = cls.client.get_state()
        # The stop applies at the allowed step (up to the window, 100 steps, ahead); then damping
        # (kappa = 4) settles the speed.
        cls.wait_steps(250)
        a = cls.pose_now()
        cls.wait_steps(100)
        cls.drift4 = math.dist(a[:2], cls.pose_now()[:2])

        # 4. Refused goals.
        bad = pose(1.0, 1.0, 0.0)
        bad.pose.orientation.w = 0.0
        cls.refused = []
        for goal in (bad, pose(1.0, 1.0, 0.0, frame="map")):
            cls.client.send_goal(MoveBaseGoal(target_pose=goal))
            cls.wait(lambda: cls.client.get_state() not in (GoalStatus.PENDING, GoalStatus.ACTIVE), 20, "a bad goal")
            cls.refused.append((cls.client.get_state(), cls.client.get_goal_status_text()))
        for s in subs:
            s.unregister()
        cls.log.unregister()

        cls.result, cls.bag, cls.commands_file, cls.expected = vf_rostest.recorded_with_commands(
            cls.out, cls.path, steps * h / 5 + 90)

    @classmethod
    def on_status(cls, msg):
        cls.step = max(cls.step, msg.step)

    @classmethod
    def wait(cls, condition, timeout, what):
        end = time.time() + timeout
        while not condition():
            if time.time() > end:
                raise AssertionError(f"timed out waiting for {what} (step {cls.step})")
            time.sleep(0.02)

    @classmethod
    def wait_steps(cls, k):
        target = cls.step + k
        cls.wait(lambda: cls.step >= target, 60, f"step {target}")

    @classmethod
    def pose_now(cls):
        return cls.log.pose_now()

    @classmethod
    def near(cls, goal, distance, angle):
        x, y, yaw = cls.pose_now()
        return math.hypot(x - goal[0], y - goal[1]) <= distance and abs(wrap(yaw - goal[2])) <= angle

    @classmethod
    def rest(cls, seconds):
        """The pose once `seconds` of simulated time have passed (the formation settled)."""
        cls.wait_steps(round(seconds / float(cls.scenario["time_step"])))
        return cls.pose_now()

    def test_action_goal_is_reached(self):
        self.assertEqual(self.state1, GoalStatus.SUCCEEDED, self.text1)
        self.assertTrue(self.feedback, "no feedback")
        x, y, yaw = self.pose1
        print(f"goal_test: goal {self.goal1}: at rest ({x:.4f}, {y:.4f}), yaw {yaw:.4f}", flush=True)
        # 5 cm / 0.05 rad when reached; the formation then slows to rest (a few mm more).
        self.assertLess(math.hypot(x - self.goal1[0], y - self.goal1[1]), 0.06)
        self.assertLess(abs(wrap(yaw - self.goal1[2])), 0.06)
        # The feedback is the centroid on the way: it starts far from the goal and ends near it.
        first, last = self.feedback[0].base_position.pose.position, self.feedback[-1].base_position.pose.position
        self.assertGreater(math.hypot(first.x - 2.0, first.y - 1.0), 1.5)
        self.assertLess(math.hypot(last.x - 2.0, last.y - 1.0), 0.5)

    def test_topic_goal_preempts_and_is_reached(self):
        self.assertEqual(self.state2, GoalStatus.PREEMPTED)
        x, y, yaw = self.pose3
        print(f"goal_test: topic goal {self.goal3}: at rest ({x:.4f}, {y:.4f}), yaw {yaw:.4f}", flush=True)
        self.assertLess(math.hypot(x - self.goal3[0], y - self.goal3[1]), 0.06)
        self.assertLess(abs(wrap(yaw - self.goal3[2])), 0.06)

    def test_cancel_stops_the_formation(self):
        self.assertEqual(self.state4, GoalStatus.PREEMPTED)
        self.assertLess(self.drift4, 0.01)

    def test_bad_goals_are_aborted_saying_why(self):
        (s1, t1), (s2, t2) = self.refused
        self.assertEqual(s1, GoalStatus.ABORTED)
        self.assertIn("goal.target_pose.pose.orientation: must be a unit quaternion", t1)
        self.assertEqual(s2, GoalStatus.ABORTED)
        self.assertIn("goal.target_pose.header.frame_id: must be the formation's frame 'world'", t2)

    def test_run_succeeds_in_shape_and_equals_simulate_on_the_commands_file(self):
        self.assertEqual(self.result.get("result"), "succeeded", f"result file: {self.result}")
        self.assertTrue(self.result["formation"].startswith("converged to the desired shape"), self.result)
        self.assertGreater(int(self.result["commands"]), 5)
        self.assertTrue(self.expected, f"no commands file {self.commands_file}")
        rec = vf_rostest.Recording(self.bag)
        steps = int(self.scenario["steps"])
        self.check_equals_simulate(rec, self.scenario, self.expected)
        # The status carries the shape error over all pairs: at the end every pair within 1 % of 2 m.
        last = rec.status[steps][0]
        self.assertLess(last.shape_error, 0.02)
        self.assertFalse(any(math.isnan(s.shape_error) for (s,) in rec.status.values()))


if __name__ == "__main__":
    rostest.rosrun("variational_formation", "goal", GoalRun)
