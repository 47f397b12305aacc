#!/usr/bin/python3
"""rostest (verdict.test): one verdict for a run, in every output (issue 50, defects 4 and 5).

Five lockstep runs through run_formation.sh on the test's master, one per ending: the desired
shape (config/hexagon.yaml), its mirror image (verdict_mirror.yaml), folded
(verdict_folded.yaml), still settling at the last step (verdict_settling.yaml, the hexagon for
robots parked near it as assign_slots writes it) and not converged (the hexagon cut to 20 steps).
For each:
- the result file's `formation:` is simulate's last line, word for word, and `verdict:` names it;
- "converged" is said only of the desired shape: in the result file (`converged_step`), the
  monitor's log, the last line, every `status` message (`converged`, `converged_step`) and
  run_formation.sh's line;
- without require_convergence the run succeeds, and the monitor's last line says what that means;
  with it (the mirror image), the run fails with the reason.
"""
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import unittest

import rospy
import rostest
import yaml
from variational_formation_msgs.msg import FormationStatus

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402

PKG = vf_rostest.PKG
HERE = os.path.dirname(os.path.abspath(__file__))


def run_formation(*args, timeout=120):
    return subprocess.run(["rosrun", PKG, "run_formation.sh", *args], capture_output=True, text=True, timeout=timeout)


def simulate_verdict(path):
    """simulate's last line on stdout, without its "formation: "."""
    with tempfile.TemporaryDirectory() as tmp:
        r = subprocess.run(["rosrun", PKG, "simulate", "--scenario", path, "--out", os.path.join(tmp, "traj.csv")],
                           capture_output=True, text=True, timeout=60)
    line = r.stdout.strip().splitlines()[-1]
    assert line.startswith("formation: "), r.stdout + r.stderr
    return line[len("formation: "):]


def says_converged(line):
    """The line calls the formation converged ("converged" not preceded by "not ")."""
    at = line.find("converged")
    while at >= 0:
        if line[max(0, at - 4):at] != "not ":
            return True
        at = line.find("converged", at + 1)
    return False


@vf_rostest.reported_setup
class VerdictTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("verdict_test")
        cls.tmp = tempfile.mkdtemp(prefix="vf_verdict_test_")
        cls.lock = threading.Lock()
        cls.statuses = []
        rospy.Subscriber("/formation/status", FormationStatus, cls.on_status, queue_size=10000)
        short = vf_rostest.load_scenario(vf_rostest.scenario_path("hexagon"))
        short = {k: v for k, v in short.items() if k not in ("n", "neighbours")}
        short["steps"] = 20
        cls.short = os.path.join(cls.tmp, "verdict_short.yaml")
        with open(cls.short, "w") as f:
            yaml.safe_dump(short, f)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    @classmethod
    def on_status(cls, msg):
        with cls.lock:
            cls.statuses.append((msg.step, msg.converged, msg.converged_step))

    def launch(self, path):
        """run_formation.sh on `path`: (its CompletedProcess, the result file, the statuses seen)."""
        with self.lock:
            self.statuses.clear()
        stem = os.path.splitext(os.path.basename(path))[0]
        out = os.path.join(self.tmp, stem)  # in the logged paths: no "converged" from a name
        run = run_formation(f"scenario:={path}", f"output_dir:={out}")
        result = vf_rostest.wait_for_result(os.path.join(out, stem + ".result.yaml"), 0)
        rospy.sleep(0.5)  # the last status, published before the result file was written
        with self.lock:
            statuses = list(self.statuses)
        return run, result, statuses

    def check_run(self, path, verdict, line_start, steps):
        expected = simulate_verdict(path)
        self.assertTrue(expected.startswith(line_start), expected)
        run, result, statuses = self.launch(path)
        log = run.stdout + run.stderr
        self.assertEqual(run.returncode, 0, log[-3000:])
        self.assertEqual(result.get("result"), "succeeded", result)
        self.assertEqual(result["formation"], expected)  # one verdict: simulate's, word for word
        self.assertEqual(result["verdict"], verdict)
        self.assertEqual(result["completed_step"], steps)
        self.assertTrue(statuses, "no status on /formation/status")
        self.assertEqual(max(s[0] for s in statuses), steps)
        desired = verdict == "desired_shape"
        monitor = [line for line in log.splitlines() if "monitor: " in line]
        last = [line for line in monitor if "monitor: run succeeded" in line]
        self.assertTrue(last, log[-3000:])
        self.assertIn("formation " + expected, last[-1])
        if desired:
            converged_at = int(expected.split()[7])
            self.assertEqual(result["converged_step"], converged_at)
            self.assertIn("monitor: run succeeded; formation converged", last[-1])
            self.assertTrue(any(f"congruent with the desired shape since step {converged_at} " in line
                                for line in monitor), log[-3000:])
            final = max(statuses)
            self.assertEqual(final[1:], (True, converged_at))
            return
        self.assertEqual(result["converged_step"], -1)
        self.assertIn(f"monitor: run succeeded: all {steps} steps ran (the scenario does not require convergence); "
                      "formation not converged", last[-1])
        for line in monitor:
            self.assertFalse(says_converged(line), line)
            self.assertNotIn("congruent with the desired shape", line)
        self.assertEqual([s for s in statuses if s[1] or s[2] != -1], [])
        self.assertIn("run_formation: the run succeeded, but the formation did not converge: ", run.stderr)
        return log

    def test_desired_shape(self):
        self.check_run(vf_rostest.scenario_path("hexagon"), "desired_shape",
                       "converged to the desired shape at step 210 ", 300)

    def test_mirror_image(self):
        path = os.path.join(HERE, "verdict_mirror.yaml")
        log = self.check_run(path, "mirror_image", "not converged: the mirror image of the desired shape from step ", 300)
        # The monitor saw it congruent, and said which hand.
        self.assertRegex(log, r"monitor: congruent with the mirror image of the desired shape since step \d+ "
                              r"\(t = [0-9.]+ s\): not converged \(mirror: forbidden\)")
        # Required: the same run fails, with the reason in the result file and run_formation.sh's line.
        with open(path) as f:
            text = f.read()
        required = os.path.join(self.tmp, "verdict_mirror_required.yaml")
        with open(required, "w") as f:
            f.write(text + "require_convergence: true\n")
        run, result, _ = self.launch(required)
        self.assertNotEqual(run.returncode, 0, run.stdout[-3000:])
        self.assertEqual(result.get("result"), "failed", result)
        self.assertEqual(result["verdict"], "mirror_image")
        reason = "the formation did not converge (its mirror image), and the scenario requires it " \
                 "(require_convergence: true)"
        self.assertEqual(result["reason"], reason)
        self.assertIn(reason, run.stderr)
        for line in (run.stdout + run.stderr).splitlines():
            if "monitor: " in line or "run_formation: " in line:
                self.assertFalse(says_converged(line), line)

    def test_folded(self):
        self.check_run(os.path.join(HERE, "verdict_folded.yaml"), "folded",
                       "not converged: folded, at rest with every edge within tolerance but not every pair", 20)

    def test_still_settling(self):
        self.check_run(os.path.join(HERE, "verdict_settling.yaml"), "still_settling",
                       "not converged: still settling at the last step (every edge within tolerance; ", 300)

    def test_not_converged(self):
        self.check_run(self.short, "not_converged", "not converged (final max distance error ", 20)


if __name__ == "__main__":
    rostest.rosrun(PKG, "verdict", VerdictTest)
