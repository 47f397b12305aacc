#!/usr/bin/python3
"""rostest (safety_monitor.test): the monitor's report of the safety filter, on timed agents whose
filter blocks the formation for ever (test/ros/blocked_line_timed.yaml: agents 1 and 2 must swap
places on a line).

- The run ends early (well before its 1000 steps), with the formation "not converged (blocked:
  agents 1, 2)" in the result file, and `succeeded` (the scenario does not require convergence).
- The result file's closest_approach is agents 1 and 2, at least r apart, and equal to the
  smallest min_separation of the statuses; filter_active_steps > 0.
- Every status carries min_separation (finite, the distance of the closest pair of the states it
  measured: checked against the agents' own states at the last step) and constraints_active,
  which is > 0 at some statuses; the agents' states carry constraints_active too.
"""
import math
import os
import shutil
import sys
import unittest

import rospy
import rostest
from variational_formation_msgs.msg import AgentState, FormationStatus

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402

NS = "/formation"


@vf_rostest.reported_setup
class SafetyMonitor(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("safety_monitor_test")
        cls.scenario = vf_rostest.load_scenario(rospy.get_param("~scenario"))
        cls.out = rospy.get_param("~output_dir")
        cls.status, cls.states = [], {}
        cls.status_sub = rospy.Subscriber(NS + "/status", FormationStatus, cls.status.append, queue_size=1000)
        cls.state_subs = [rospy.Subscriber(f"{NS}/agent_{i}/state", AgentState,
                                           lambda m: cls.states.setdefault(m.id, []).append(m), queue_size=1000)
                          for i in range(cls.scenario["n"])]
        path = os.path.join(cls.out, "blocked_line_timed.result.yaml")
        cls.result = vf_rostest.wait_for_result(path, 45.0)
        # The last status and every agent's last state (the checks below read both).
        done = int(cls.result.get("completed_step", -1))
        arrived = lambda: (cls.status and cls.status[-1].step >= done  # noqa: E731
                           and all(cls.states.get(i) and cls.states[i][-1].step >= done for i in range(cls.scenario["n"])))
        assert vf_rostest.wait_until(arrived, 10.0), f"the status and states of step {done} did not arrive in 10 s"
        cls.status_sub.unregister()
        for s in cls.state_subs:
            s.unregister()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.out, ignore_errors=True)

    def test_run_ends_blocked_early(self):
        print(f"result: {self.result}", flush=True)
        self.assertEqual(self.result.get("result"), "succeeded", self.result)
        self.assertEqual(self.result.get("formation"), "not converged (blocked: agents 1, 2)", self.result)
        self.assertLess(int(self.result["completed_step"]), 600, self.result)

    def test_closest_approach_and_filter_steps(self):
        r = self.scenario["safety"]["radius"]
        closest = self.result.get("closest_approach")
        self.assertIsInstance(closest, dict, self.result)
        self.assertEqual(closest["agents"], [1, 2])
        self.assertGreaterEqual(closest["distance"], r)
        self.assertLess(closest["distance"], r + 0.2)  # they were pressed together
        separations = [s.min_separation for s in self.status]
        self.assertTrue(separations, "no status")
        self.assertAlmostEqual(closest["distance"], min(separations), delta=1e-12)
        self.assertGreater(int(self.result["filter_active_steps"]), 0)

    def test_every_status_reports_the_filter(self):
        self.assertTrue(all(math.isfinite(s.min_separation) for s in self.status))
        self.assertTrue(any(s.constraints_active > 0 for s in self.status))
        for i in (1, 2):
            self.assertTrue(any(m.constraints_active > 0 for m in self.states.get(i, [])), f"agent_{i}")
        # The last status measured every agent's newest state: once the agents stopped, their
        # last states; its min_separation is their closest pair.
        last = {i: msgs[-1].position for i, msgs in self.states.items()}
        pairs = [math.dist(last[a], last[b]) for a in last for b in last if a < b]
        self.assertAlmostEqual(self.status[-1].min_separation, min(pairs), delta=1e-3)


if __name__ == "__main__":
    rostest.rosrun("variational_formation", "safety_monitor_test", SafetyMonitor)
