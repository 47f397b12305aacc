#!/usr/bin/python3
"""rostest (diverging_safety.test): issue 50, a run with the safety filter on that diverges ends,
by itself, as a run without it does.

The README's deploy6 (make_scenario --shape ring --agents 6 --chords 2 --scatter 4 --min-gap 0.4
--seed 3 --safety 0.25 1 0.2) at h = 0.5, above its stability limit:
- simulate ends at its first non-finite step with the divergence line and exit status 1 (it used
  to hang in the closest pair search);
- formation.launch, run by roslaunch on the test's master as a user runs it, ends by itself, three
  times in a row: the monitor names the agent that diverged and its step (simulate's first
  non-finite step of that agent), the result file says `result: failed` with that reason, and
  roslaunch exits within 10 s of the monitor's failure (the monitor used to spin, the result file
  to stay `result: running`, and roslaunch to need SIGKILL).
- A state that is not finite from an agent's own node (one that does not undo its step) also
  ends the run as diverged: formation.launch with agents:=false and a stand-in agent_0.
"""
import csv
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import rospy
import rostest
import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import vf_rostest  # noqa: E402

PKG = vf_rostest.PKG
ENDS_WITHIN = 10.0  # s from the monitor's failure to roslaunch's exit (issue 50)
TRIES = 3


def first_nonfinite_steps(traj):
    """{agent: first step whose position is not finite} of a traj.csv, and its last step."""
    first, last = {}, -1
    with open(traj) as f:
        for row in csv.DictReader(f):
            i, k = int(row["agent"]), int(row["step"])
            last = max(last, k)
            if not all(math.isfinite(float(row[c])) for c in "xy"):
                first.setdefault(i, k)
    return first, last


@vf_rostest.reported_setup
class DivergingSafetyTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("diverging_safety_test")
        cls.tmp = tempfile.mkdtemp(prefix="vf_diverging_")
        cls.path = os.path.join(cls.tmp, "deploy6.yaml")
        made = subprocess.run(["rosrun", PKG, "make_scenario", "--shape", "ring", "--agents", "6", "--chords", "2",
                               "--scatter", "4", "--min-gap", "0.4", "--seed", "3", "--safety", "0.25", "1", "0.2",
                               "--time-step", "0.02", "--steps", "3000", "--out", cls.path],
                              capture_output=True, text=True, timeout=60)
        assert made.returncode == 0, made.stderr
        with open(cls.path) as f:
            s = yaml.safe_load(f)
        s["time_step"] = 0.5  # above the stability limit: the run blows up within a few steps
        with open(cls.path, "w") as f:
            yaml.safe_dump(s, f)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def simulate(self):
        traj = os.path.join(self.tmp, "traj.csv")
        started = time.time()
        run = subprocess.run(["rosrun", PKG, "simulate", "--scenario", self.path, "--out", traj],
                             capture_output=True, text=True, timeout=60)
        return run, time.time() - started, traj

    def test_simulate_ends_at_the_first_nonfinite_step(self):
        run, seconds, traj = self.simulate()
        rospy.loginfo("diverging_safety: simulate ended in %.2f s (exit %d)", seconds, run.returncode)
        self.assertEqual(run.returncode, 1, run.stderr)
        first, last = first_nonfinite_steps(traj)
        self.assertTrue(first, "the scenario does not diverge")
        self.assertEqual(min(first.values()), last, "simulate went on after the first non-finite step")
        self.assertTrue(run.stderr.endswith(
            f"simulate: error: the run diverged: non-finite positions from step {last} (try a smaller --time-step)\n"),
            run.stderr)
        self.assertLess(seconds, ENDS_WITHIN)

    def launch(self, out, *args):
        """roslaunch formation.launch in its own session; (output, seconds to the failure in the
        result file, seconds to roslaunch's exit), or a failure if it does not exit in 60 s."""
        result_path = os.path.join(out, "deploy6.result.yaml")
        started = time.time()
        run = subprocess.Popen(["roslaunch", PKG, "formation.launch", f"scenario:={self.path}", f"output_dir:={out}",
                                *args], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                               start_new_session=True)
        failed_at = None
        try:
            while run.poll() is None and time.time() - started < 60:
                if failed_at is None and vf_rostest.wait_for_result(result_path, 0).get("result") == "failed":
                    failed_at = time.time() - started
                time.sleep(0.05)
            if run.poll() is None:
                os.killpg(run.pid, signal.SIGKILL)
                out_text, _ = run.communicate(timeout=30)
                self.fail(f"roslaunch did not exit within 60 s (result file: "
                          f"{vf_rostest.wait_for_result(result_path, 0)}):\n{out_text[-3000:]}")
            out_text, _ = run.communicate(timeout=30)
        finally:
            if run.poll() is None:
                os.killpg(run.pid, signal.SIGKILL)
                run.wait()
        exited_at = time.time() - started
        if failed_at is None and vf_rostest.wait_for_result(result_path, 0).get("result") == "failed":
            failed_at = exited_at
        return out_text, failed_at, exited_at

    def test_the_launch_fails_naming_the_agent_and_ends_by_itself(self):
        run, _, traj = self.simulate()
        first, _ = first_nonfinite_steps(traj)
        self.assertTrue(first, run.stderr)
        for attempt in range(TRIES):
            out = os.path.join(self.tmp, f"launch{attempt}")
            log, failed_at, exited_at = self.launch(out)
            where = f"try {attempt + 1}: {log[-3000:]}"
            self.assertIsNotNone(failed_at, where)
            rospy.loginfo("diverging_safety: try %d: failed %.2f s after the launch, roslaunch exited %.2f s after "
                          "the launch (%.2f s after the failure)", attempt + 1, failed_at, exited_at,
                          exited_at - failed_at)
            with open(os.path.join(out, "deploy6.result.yaml")) as f:
                result = yaml.safe_load(f)
            self.assertEqual(result["result"], "failed", where)
            named = re.fullmatch(r"/formation/agent_(\d+): step (\d+) is not finite \(the run diverged\)", result["reason"])
            self.assertIsNotNone(named, result["reason"])
            agent, step = int(named.group(1)), int(named.group(2))
            self.assertEqual(step, first.get(agent), f"{result['reason']}; simulate: {first}")
            failed = [line for line in log.splitlines() if "monitor: run failed at step" in line]
            self.assertEqual(len(failed), 1, where)
            self.assertIn(result["reason"], failed[0])
            self.assertLess(exited_at - failed_at, ENDS_WITHIN, where)

    def test_a_nonfinite_state_from_its_own_agent_ends_the_run(self):
        out = os.path.join(self.tmp, "stand_in")
        # agent_0 is a stand-in that publishes a non-finite state on its own topic; no other agent
        # starts, so the run can only end through the monitor's check.
        stand_in = subprocess.Popen([sys.executable, os.path.join(HERE, "nonfinite_agent.py"), "__name:=agent_0",
                                     "__ns:=/formation"],
                                    stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                    start_new_session=True)
        try:
            log, failed_at, exited_at = self.launch(out, "agents:=false")
        finally:
            os.killpg(stand_in.pid, signal.SIGINT)
            stand_in.communicate(timeout=30)
        self.assertIsNotNone(failed_at, log[-3000:])
        with open(os.path.join(out, "deploy6.result.yaml")) as f:
            result = yaml.safe_load(f)
        self.assertEqual(result["result"], "failed", log[-3000:])
        self.assertEqual(result["reason"], "/formation/agent_0: step 0 is not finite (the run diverged)")
        self.assertLess(exited_at - failed_at, ENDS_WITHIN, log[-3000:])


if __name__ == "__main__":
    rostest.rosrun(PKG, "diverging_safety", DivergingSafetyTest)
