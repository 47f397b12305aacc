#!/usr/bin/python3
"""rostest (safety_run.test): a recorded lockstep run with the safety filter on.

Private parameters:
  scenario    the scenario file (a `safety:` block under which the filter binds)
  fault       none | kill: SIGKILL to the process of the first agent that publishes a step its
              filter bound (constraints_active > 0) at step >= 60 (with nodelet: the manager),
              at once; it is respawned and recovers
  nodelet     the agents ran in formation/manager
  output_dir  where formation.launch writes the bag and the result file (removed after)
"""
import os
import shutil
import signal
import sys
import threading
import time
import unittest

import rospy
import rostest
from variational_formation_msgs.msg import AgentState

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402

NS = "/formation"


@vf_rostest.reported_setup
class SafetyRun(unittest.TestCase, vf_rostest.RunChecks):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("safety_run_test")
        cls.fault = rospy.get_param("~fault", "none")
        cls.nodelet = bool(rospy.get_param("~nodelet", False))
        cls.out = rospy.get_param("~output_dir")
        cls.path = rospy.get_param("~scenario")
        cls.scenario = vf_rostest.load_scenario(cls.path)
        cls.name = os.path.basename(cls.path).replace(".yaml", "")
        n = cls.scenario["n"]
        cls.lock = threading.Lock()
        cls.binding = None  # (agent, step) of the first live state whose filter bound, at step >= 60
        cls.killed = None

        cls.heard = 0

        def on_state(msg, i):
            with cls.lock:
                cls.heard += 1
                if cls.binding is None and cls.pids and msg.id == i and msg.step >= 60 and msg.constraints_active > 0:
                    cls.binding = (i, msg.step)
                    if cls.fault == "kill" and cls.killed is None:
                        # At once, from the callback: the agent is still where its filter binds.
                        victim = f"{NS}/manager" if cls.nodelet else f"{NS}/agent_{i}"
                        os.kill(cls.pids[victim], signal.SIGKILL)
                        cls.killed = (victim, i, msg.step)

        # Subscribed first: the run starts without waiting for this test, and binds early.
        cls.pids = {}
        cls.subs = [rospy.Subscriber(f"{NS}/agent_{i}/state", AgentState, on_state, i, queue_size=10000)
                    for i in range(n)]
        victims = [f"{NS}/manager"] if cls.nodelet else [f"{NS}/agent_{i}" for i in range(n)]
        pids = {v: vf_rostest.node_pid(v) for v in victims}
        with cls.lock:
            cls.pids = pids
        cls.result = vf_rostest.wait_for_result(os.path.join(cls.out, cls.name + ".result.yaml"), 90.0)
        for s in cls.subs:
            s.unregister()
        if cls.killed:
            rospy.loginfo("safety_run_test: SIGKILL to %s right after agent_%d published step %d with its filter "
                          "binding", *cls.killed)
        cls.expected = vf_rostest.simulate(cls.path)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.out, ignore_errors=True)

    def test_recording_equals_simulate_and_the_filter_bound(self):
        self.assertEqual(self.result.get("result"), "succeeded", f"result file: {self.result}")
        rec = vf_rostest.Recording(os.path.join(self.out, self.name + ".bag"))
        n, steps = self.scenario["n"], int(self.scenario["steps"])
        self.check_each_step_once(rec, n, steps)
        mismatches = [key for key, msgs in rec.states.items() for m in msgs
                      if list(m.position) != self.expected[key]
                      or list(m.previous_position) != self.expected[(key[0], max(key[1] - 1, 0))]]
        self.assertEqual(mismatches[:10], [], f"{len(mismatches)} recorded states differ from simulate")
        bound = sorted(key for key, (m,) in rec.states.items() if m.constraints_active > 0)
        self.assertGreater(len(bound), 10, "the filter must bind for this test to mean anything")
        self.assertIsNotNone(self.binding, f"no live state with constraints_active > 0 among {self.heard} seen")
        # A pair closer than r would mean the filter was not applied as simulate applies it.
        r = float(self.scenario["safety"]["radius"])
        for k in range(steps + 1):
            q = [rec.states[(i, k)][0].position for i in range(n)]
            closest = min(sum((a - b) ** 2 for a, b in zip(q[i], q[j])) ** 0.5
                          for i in range(n) for j in range(i + 1, n))
            self.assertGreaterEqual(closest, r - 1e-9, f"step {k}")

    def test_the_fault_as_asked(self):
        if self.fault == "none":
            self.assertIsNone(self.killed)
            return
        self.assertIsNotNone(self.killed, "no agent was killed")
        victim, agent, step = self.killed
        self.assertLess(step, int(self.scenario["steps"]) - 20, "killed too close to the end to test recovery")
        self.assertNotEqual(vf_rostest.node_pid(victim), self.pids[victim], f"{victim} was not respawned")


if __name__ == "__main__":
    rostest.rosrun(vf_rostest.PKG, "safety_run_test", SafetyRun, sys.argv)
