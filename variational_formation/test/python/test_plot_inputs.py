#!/usr/bin/python3
"""The plotting scripts read what the package records, and refuse what does not belong together.

- plot_bag.py reads every part of a split recording, finds the formation's namespace in the
  bag (or takes --ns, and asks for it when a bag holds several), and takes a scenario name.
- plot_bag.py, plot_simulation.py and plot_roa.py refuse a scenario of another formation (agent
  count, dimension) or files that do not fit each other: one line, exit status 2.
- --help of each plotting script gives its whole first paragraph.
Bags are written here from simulate's own run of the square (40 steps), under /team_a/formation.
"""
import csv
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import rosbag
import rospy
from geometry_msgs.msg import Vector3
from variational_formation_msgs.msg import AgentState, FormationStatus

PKG = "variational_formation"
SCRIPTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts")
STEPS = 40


def script(name, *args):
    """(exit status, stdout, stderr) of one of the package's scripts."""
    run = subprocess.run(["/usr/bin/python3", os.path.join(SCRIPTS, name), *args], capture_output=True, text=True,
                         timeout=120, env=dict(os.environ, MPLCONFIGDIR=tempfile.gettempdir()))
    return run.returncode, run.stdout, run.stderr


def simulate(scenario, out_dir, steps=STEPS):
    traj, metrics = os.path.join(out_dir, scenario + "_traj.csv"), os.path.join(out_dir, scenario + "_metrics.csv")
    subprocess.run(["rosrun", PKG, "simulate", "--scenario", scenario, "--out", traj, "--metrics", metrics, "--steps",
                    str(steps)], check=True, capture_output=True)
    return traj, metrics


def write_bag(parts, traj, metrics, dimension, ns):
    """The run of traj/metrics as the recorder writes it: states and status per step, the steps
    spread over `parts` bag files in order."""
    with open(traj) as f:
        rows = list(csv.DictReader(f))
    with open(metrics) as f:
        status = list(csv.DictReader(f))
    bags = [rosbag.Bag(p, "w") for p in parts]
    per_part = (STEPS + 1 + len(parts) - 1) // len(parts)
    for r in rows:
        k = int(r["step"])
        msg = AgentState(id=int(r["agent"]), step=k, time=float(r["t"]),
                         position=[float(r[c]) for c in "xyz"[:dimension]])
        bags[k // per_part].write(f"{ns}/agent_{r['agent']}/state", msg, rospy.Time.from_sec(1 + float(r["t"])))
    for m in status:
        k = int(m["step"])
        msg = FormationStatus(step=k, time=float(m["t"]), energy=float(m["energy"]),
                              max_distance_error=float(m["max_distance_error"]),
                              linear_momentum=Vector3(float(m["px"]), float(m["py"]), float(m["pz"])),
                              angular_momentum=Vector3(float(m["ax"]), float(m["ay"]), float(m["az"])),
                              converged_step=-1)
        bags[k // per_part].write(f"{ns}/status", msg, rospy.Time.from_sec(1 + float(m["t"])))
    for bag in bags:
        bag.close()


class PlotInputs(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="vf_plot_inputs_")
        cls.square = simulate("square", cls.tmp)
        cls.tetrahedron = simulate("tetrahedron", cls.tmp)
        cls.hexagon = simulate("hexagon", cls.tmp)
        cls.split = os.path.join(cls.tmp, "team_a_square.bag")
        write_bag([cls.split, os.path.join(cls.tmp, "team_a_square_1.bag")], *cls.square, 2, "/team_a/formation")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def assert_refused(self, run, *words):
        status, out, err = run
        self.assertEqual(status, 2, out + err)
        self.assertEqual(len(err.strip().splitlines()), 1, err)
        for w in words:
            self.assertIn(w, err)

    def test_split_namespaced_bag_is_read_whole(self):
        status, out, err = script("plot_bag.py", "--bag", self.split, "--scenario", "square", "--out-dir", self.tmp)
        self.assertEqual(status, 0, err)
        self.assertIn(f"steps: {STEPS},", out)
        self.assertIn("read 2 bag files", out)
        self.assertIn("formation /team_a/formation", out)
        self.assertTrue(os.path.isfile(os.path.join(self.tmp, "square_energy.png")))

    def test_bag_with_two_formations_needs_ns(self):
        both = os.path.join(self.tmp, "both.bag")
        write_bag([both], *self.square, 2, "/team_a/formation")
        with rosbag.Bag(both, "a") as bag, rosbag.Bag(self.split) as other:
            for topic, msg, t in other.read_messages():
                bag.write(topic.replace("/team_a/", "/team_b/"), msg, t)
        self.assert_refused(script("plot_bag.py", "--bag", both, "--scenario", "square", "--out-dir", self.tmp),
                            "several formations", "/team_a/formation", "/team_b/formation", "--ns")
        status, out, err = script("plot_bag.py", "--bag", both, "--scenario", "square", "--ns", "team_b/formation",
                                  "--out-dir", self.tmp)
        self.assertEqual(status, 0, err)
        self.assertIn("formation /team_b/formation", out)
        self.assert_refused(script("plot_bag.py", "--bag", both, "--scenario", "square", "--ns", "/nobody"),
                            "--ns: no /nobody/status")

    def test_bag_of_another_formation_is_refused(self):
        self.assert_refused(script("plot_bag.py", "--bag", self.split, "--scenario", "hexagon"),
                            "4 agents", "hexagon has 6", "do not belong together")
        # Same agent count, other dimension.
        self.assert_refused(script("plot_bag.py", "--bag", self.split, "--scenario", "tetrahedron"),
                            "2 coordinates", "3D", "do not belong together")

    def test_trajectory_of_another_formation_is_refused(self):
        traj, metrics = self.hexagon  # 6 agents: 41 steps x 6 rows, not a multiple of 4
        self.assert_refused(script("plot_simulation.py", "--scenario", "square", "--traj", traj, "--metrics", metrics,
                                   "--out-dir", self.tmp), "6 agents", "square has 4", "do not belong together")
        traj, metrics = self.tetrahedron  # 4 agents as the square, but in 3D
        self.assert_refused(script("plot_simulation.py", "--scenario", "square", "--traj", traj, "--metrics", metrics,
                                   "--out-dir", self.tmp), "leaves the plane", "do not belong together")
        traj, _ = self.square
        short = os.path.join(self.tmp, "short")
        os.makedirs(short, exist_ok=True)
        _, metrics = simulate("square", short, steps=10)  # fewer steps than the trajectory
        self.assert_refused(script("plot_simulation.py", "--scenario", "square", "--traj", traj, "--metrics", metrics,
                                   "--out-dir", self.tmp), "do not belong together")

    def test_matching_trajectory_is_plotted_by_name(self):
        status, out, err = script("plot_simulation.py", "--scenario", "square", "--traj", self.square[0], "--metrics",
                                  self.square[1], "--out-dir", self.tmp)
        self.assertEqual(status, 0, err)
        self.assertIn(f"steps: {STEPS},", out)

    def test_separation_is_plotted_against_r_with_a_safety_block(self):
        # test/scenarios/blocked_line.yaml: its agents 1 and 2 are held r = 0.25 m apart.
        scenario = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenarios", "blocked_line.yaml")
        traj, metrics = os.path.join(self.tmp, "blocked_traj.csv"), os.path.join(self.tmp, "blocked_metrics.csv")
        subprocess.run(["rosrun", PKG, "simulate", "--scenario", scenario, "--out", traj, "--metrics", metrics,
                        "--steps", "200"], capture_output=True)  # exit status 0 or 1: it is blocked
        status, out, err = script("plot_simulation.py", "--scenario", scenario, "--traj", traj, "--metrics", metrics,
                                  "--out-dir", self.tmp, "--prefix", "blocked")
        self.assertEqual(status, 0, err)
        self.assertIn(f"wrote {os.path.join(self.tmp, 'blocked_separation.png')}", out)
        self.assertGreater(os.path.getsize(os.path.join(self.tmp, "blocked_separation.png")), 1000)
        # Without a safety block there is no separation to plot.
        self.assertFalse(os.path.exists(os.path.join(self.tmp, "square_separation.png")))

    def test_roa_map_of_another_formation_is_refused(self):
        roa = os.path.join(self.tmp, "roa.csv")
        subprocess.run(["rosrun", PKG, "roa", "--scenario", "hexagon", "--agent", "1", "--x-range", "-1", "1",
                        "--y-range", "-1", "1", "--resolution", "3", "2", "--steps", "20", "--out", roa], check=True,
                       capture_output=True)
        png = os.path.join(self.tmp, "roa.png")
        status, _, err = script("plot_roa.py", "--roa", roa, "--scenario", "hexagon", "--agent", "1", "--out", png)
        self.assertEqual(status, 0, err)
        self.assert_refused(script("plot_roa.py", "--roa", roa, "--scenario", "square", "--agent", "5", "--out", png),
                            "--agent", "square has 4 agents")
        with open(roa) as f:
            lines = f.readlines()
        partial = os.path.join(self.tmp, "partial.csv")
        with open(partial, "w") as f:
            f.writelines(lines[:-1])
        self.assert_refused(script("plot_roa.py", "--roa", partial, "--scenario", "hexagon", "--agent", "1", "--out",
                                   png), "not one whole grid")

    def test_help_gives_the_whole_first_paragraph(self):
        for name, words in (("plot_bag.py", "and prints the summary: the same PNGs as plot_simulation.py, from the "
                             "agents' states and the monitor's status."),
                            ("plot_simulation.py", "into PNGs and prints a summary."),
                            ("plot_roa.py", "in the manner of the paper's Section 6.2."),
                            ("euler_comparison.py", "over the same simulated time.")):
            status, out, err = script(name, "--help")
            self.assertEqual(status, 0, err)
            self.assertIn(words, " ".join(out.split()), name)


if __name__ == "__main__":
    import rosunit
    rosunit.unitrun(PKG, "plot_inputs", PlotInputs)
