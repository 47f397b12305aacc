#!/usr/bin/python3
"""rostest: watches a distributed run (launch/formation.launch) and checks it.

Private parameters:
  scenario          name in config/ (required)
  expect            converged | planar | free_particle
  real_time_factor  if > 0, the run must take steps * h / real_time_factor of wall time
Every run is checked for: each agent's states 0..N exactly once (no gap, no duplicate), every
agent's every step equal to `simulate`'s bit for bit, the status of every step, and the
Noether laws on the status messages.
"""
import csv
import math
import os
import subprocess
import sys
import tempfile
import threading
import unittest

import rospkg
import rospy
import rostest
import yaml
from variational_formation.msg import AgentState, FormationStatus

PKG = "variational_formation"


class DistributedRun(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("distributed_run_test")
        name = rospy.get_param("~scenario")
        cls.expect = rospy.get_param("~expect", "converged")
        cls.path = os.path.join(rospkg.RosPack().get_path(PKG), "config", name + ".yaml")
        with open(cls.path) as f:
            cls.scenario = yaml.safe_load(f)
        cls.n = len(cls.scenario["agents"])
        cls.steps = int(cls.scenario["steps"])
        cls.h = float(cls.scenario["time_step"])
        cls.kappa = float(cls.scenario["kappa"])
        cls.states = {i: [] for i in range(cls.n)}
        cls.status = []
        cls.lock = threading.Lock()
        cls.done = threading.Event()

        def on_state(msg, i):
            if msg.header.frame_id == "injected":  # inject_malformed.py's, not the agent's
                return
            with cls.lock:
                cls.states[i].append(msg)

        def on_status(msg):
            with cls.lock:
                cls.status.append(msg)
            if msg.step >= cls.steps:
                cls.done.set()

        cls.subs = [rospy.Subscriber(f"/formation/agent_{i}/state", AgentState, on_state, i, queue_size=100000)
                    for i in range(cls.n)]
        cls.subs.append(rospy.Subscriber("/formation/status", FormationStatus, on_status, queue_size=100000))
        cls.finished = cls.done.wait(timeout=float(rospy.get_param("~timeout", 90.0)))
        rospy.sleep(0.5)  # the agents' last states trail the last status by nothing; be generous

    def test_00_run_finished(self):
        self.assertTrue(self.finished, "no status for the last step arrived")

    def test_every_step_of_every_agent_exactly_once(self):
        for i in range(self.n):
            steps = [m.step for m in self.states[i]]
            self.assertEqual(steps, list(range(self.steps + 1)), f"agent {i}")
        self.assertEqual([s.step for s in self.status], list(range(self.steps + 1)))

    def test_bitwise_equal_to_simulate(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "traj.csv")
            subprocess.run(["rosrun", PKG, "simulate", "--scenario", self.path, "--out", out], check=True)
            with open(out) as f:
                rows = list(csv.DictReader(f))
        self.assertEqual(len(rows), (self.steps + 1) * self.n)
        d = int(self.scenario["dimension"])
        mismatches = 0
        for row in rows:
            k, i = int(row["step"]), int(row["agent"])
            expected = [float(row[c]) for c in "xyz"[:d]]
            got = list(self.states[i][k].position)
            if got != expected:  # exact: %.17g round-trips a double
                mismatches += 1
        self.assertEqual(mismatches, 0, f"{mismatches} of {len(rows)} positions differ from simulate")

    def test_pacing(self):
        # With a real-time factor r, step k is due k h / r after step 0.
        rtf = float(rospy.get_param("~real_time_factor", 0.0))
        if rtf > 0.0:
            first, last = self.status[0].header.stamp, self.status[-1].header.stamp
            due = self.steps * self.h / rtf
            self.assertGreater((last - first).to_sec(), 0.95 * due)
            self.assertLess((last - first).to_sec(), 1.5 * due + 1.0)

    def test_noether_laws_on_status(self):
        for s in self.status:
            for x, pred in ((s.linear_momentum, s.linear_momentum_predicted),
                            (s.angular_momentum, s.angular_momentum_predicted)):
                scale = max(1.0, math.sqrt(pred.x ** 2 + pred.y ** 2 + pred.z ** 2))
                err = math.sqrt((x.x - pred.x) ** 2 + (x.y - pred.y) ** 2 + (x.z - pred.z) ** 2)
                self.assertLess(err / scale, 1e-9, f"step {s.step}")

    def test_expected_outcome(self):
        last = self.status[-1]
        if self.expect == "converged":
            self.assertTrue(last.converged, f"max distance error {last.max_distance_error}")
            self.assertGreaterEqual(last.converged_step, 0)
            self.assertLess(last.max_distance_error, 0.05)
            self.assertLess(last.energy, 1e-2 * self.status[0].energy)
        elif self.expect == "planar":
            # The paper's start lies in the plane 3x - y = 3 and never leaves it.
            for i in range(self.n):
                for m in self.states[i]:
                    x, y, _ = m.position
                    self.assertLess(abs(3 * x - y - 3), 1e-9, f"agent {i} step {m.step}")
            self.assertFalse(last.converged)
        elif self.expect == "free_particle":
            # v_{k+1} = e^{-kappa h} v_k exactly, to the round-off of difference quotients.
            a = math.exp(-self.kappa * self.h)
            states = self.states[0]
            for k in range(2, self.steps + 1):
                v1 = [(p - q) / self.h for p, q in zip(states[k].position, states[k].previous_position)]
                v0 = [(p - q) / self.h for p, q in zip(states[k - 1].position, states[k - 1].previous_position)]
                for c in range(3):
                    self.assertAlmostEqual(v1[c], a * v0[c], delta=1e-10)
        else:
            self.fail(f"unknown ~expect {self.expect}")


if __name__ == "__main__":
    rostest.rosrun(PKG, "distributed_run_test", DistributedRun, sys.argv)
