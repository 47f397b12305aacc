#!/usr/bin/python3
"""rostest (goal_window.test): a goal at h = 0.02 with the default window (100 steps: a command
applies up to 2 s after the status it was computed from), on goal_deploy6 (the README's deploy6
with safety, 1500 steps), at rate 5.

Issue 50: there the formation went past a goal 3 m east and the action was aborted ("no progress
for 5 s ... (blocked?)") although the safety filter never bound. Here:
1. a goal at (1e300, 1e300) is refused at once, saying the run ends long before it is reached;
2. once formed, a goal 3 m east of the centroid, turned by 0.5 rad, succeeds, and the formation
   comes to rest within the tolerances (5 cm, 0.05 rad) plus 1 cm / 0.01 rad, the pose computed
   here from the agents' own states; its centroid never passes more than 5 cm beyond the goal;
3. the run succeeds, and `simulate --commands` on the recorder's commands file equals every
   recorded state bit for bit.
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
from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402

NS = "/formation"


@vf_rostest.reported_setup
class GoalWindowRun(unittest.TestCase, vf_rostest.RunChecks):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("goal_window_test")
        cls.out = rospy.get_param("~output_dir")
        cls.path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "goal_deploy6.yaml")
        cls.scenario = vf_rostest.load_scenario(cls.path)
        steps, h = int(cls.scenario["steps"]), float(cls.scenario["time_step"])
        log = vf_rostest.AgentStates(NS, cls.scenario)
        watcher = vf_rostest.StepWatcher(f"{NS}/status")
        client = actionlib.SimpleActionClient(f"{NS}/move_to", MoveBaseAction)
        assert watcher.wait_for_step(400, 120), f"the run did not reach step 400 (step {watcher.step})"
        assert client.wait_for_server(rospy.Duration(30)), "no action server formation/move_to"

        # 1. Far beyond what the run's 30 s allow: refused at once.
        cls.far = cls.send(client, vf_rostest.goal_pose(1e300, 1e300, 0.0), 20)

        # 2. 3 m east, turned by 0.5 rad.
        x, y, yaw = log.pose_now()
        cls.goal = (x + 3.0, y, vf_rostest.wrap(yaw + 0.5))
        cls.sent_at = watcher.step
        cls.reached = cls.send(client, vf_rostest.goal_pose(*cls.goal), 120)
        cls.reached_at = watcher.step
        assert watcher.wait_for_step(watcher.step + round(4.0 / h), 60), "the run stopped after the goal"
        cls.rest = log.pose_now()
        cls.path_x = [vf_rostest.formation_pose(list(log.states[k].values()), log.desired)[0]
                      for k in log.complete() if k >= cls.sent_at]
        log.unregister()
        watcher.unregister()

        cls.result, cls.bag, cls.commands_file, cls.expected = vf_rostest.recorded_with_commands(
            cls.out, cls.path, steps * h / 5 + 90)

    @classmethod
    def send(cls, client, pose, timeout):
        """Sends a goal and waits for its end: (status, status text)."""
        client.send_goal(MoveBaseGoal(target_pose=pose))
        end = time.time() + timeout
        while client.get_state() in (GoalStatus.PENDING, GoalStatus.ACTIVE):
            assert time.time() < end, f"goal {pose.pose.position} still active after {timeout} s"
            time.sleep(0.02)
        return client.get_state(), client.get_goal_status_text()

    def test_far_goal_is_refused_saying_the_run_ends_first(self):
        state, text = self.far
        self.assertEqual(state, GoalStatus.ABORTED, text)
        self.assertTrue(text.startswith("goal.target_pose.pose.position: (1e+300, 1e+300) is "), text)
        self.assertIn("m/s that takes at least", text)
        self.assertIn("s, and the run ends in", text)

    def test_goal_at_h_002_and_window_100_is_reached_without_overshoot(self):
        state, text = self.reached
        print(f"goal_window_test: goal {self.goal} {GoalStatus.to_string(state)} '{text}' after "
              f"{(self.reached_at - self.sent_at) * float(self.scenario['time_step']):.2f} s; at rest {self.rest}; "
              f"furthest east {max(self.path_x) - self.goal[0]:+.4f} m", flush=True)
        self.assertEqual(state, GoalStatus.SUCCEEDED, text)
        x, y, yaw = self.rest
        self.assertLess(math.hypot(x - self.goal[0], y - self.goal[1]), 0.06)
        self.assertLess(abs(vf_rostest.wrap(yaw - self.goal[2])), 0.06)
        self.assertLess(max(self.path_x), self.goal[0] + 0.05)

    def test_run_succeeds_and_equals_simulate_on_the_commands_file(self):
        self.assertEqual(self.result.get("result"), "succeeded", f"result file: {self.result}")
        self.assertGreater(int(self.result["commands"]), 3)
        self.assertTrue(self.expected, f"no commands file {self.commands_file}")
        self.check_equals_simulate(vf_rostest.Recording(self.bag), self.scenario, self.expected)


if __name__ == "__main__":
    rostest.rosrun("variational_formation", "goal_window", GoalWindowRun)
