#!/usr/bin/python3
"""Scenario names everywhere: the Python package's data.scenario_path looks a bare name up as the
C++ tools do (ROS_PACKAGE_PATH's package first, then beside the package), a path that exists
wins, and an unknown name is one line listing the places; every tool and script that takes
--scenario accepts a name (the C++ resolution itself is test_scenario_path).
"""
import contextlib
import io
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

SOURCE = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
sys.path.insert(0, os.path.join(SOURCE, "src"))
from variational_formation import data  # noqa: E402

PKG = "variational_formation"
CONFIG = os.path.join(SOURCE, "config")


class ScenarioNames(unittest.TestCase):
    def setUp(self):
        self.env = dict(os.environ)
        self.cwd = os.getcwd()
        self.tmp = tempfile.mkdtemp(prefix="vf_scenario_names_")
        os.chdir(self.tmp)
        os.environ.pop("ROS_PACKAGE_PATH", None)

    def tearDown(self):
        os.chdir(self.cwd)
        os.environ.clear()
        os.environ.update(self.env)
        shutil.rmtree(self.tmp, ignore_errors=True)

    def same(self, a, b):
        self.assertEqual(os.path.realpath(a), os.path.realpath(b))

    def test_name_without_ros(self):
        self.same(data.scenario_path("hexagon"), os.path.join(CONFIG, "hexagon.yaml"))
        self.same(data.scenario_path("hexagon.yaml"), os.path.join(CONFIG, "hexagon.yaml"))
        self.assertEqual(data.read_scenario("hexagon").n, 6)

    def test_ros_package_path_first(self):
        package = os.path.join(self.tmp, "ws", "variational_formation")
        os.makedirs(os.path.join(package, "config"))
        with open(os.path.join(package, "config", "hexagon.yaml"), "w") as f:
            f.write("x")
        os.environ["ROS_PACKAGE_PATH"] = "/nonexistent:" + os.path.join(self.tmp, "ws")
        self.assertEqual(data.scenario_path("hexagon"), os.path.join(package, "config", "hexagon.yaml"))
        self.same(data.scenario_path("square"), os.path.join(CONFIG, "square.yaml"))

    def test_existing_path_wins(self):
        with open("hexagon", "w") as f:
            f.write("x")
        self.assertEqual(data.scenario_path("hexagon"), "hexagon")
        os.makedirs("square")  # a folder is not a scenario file
        self.same(data.scenario_path("square"), os.path.join(CONFIG, "square.yaml"))
        self.assertEqual(data.scenario_path("no/such.yaml"), "no/such.yaml")

    def test_unknown_name_is_one_line_listing_the_places(self):
        err = io.StringIO()
        with contextlib.redirect_stderr(err), self.assertRaises(SystemExit) as exit_:
            data.scenario_path("hexagn")
        self.assertEqual(exit_.exception.code, 2)
        line = err.getvalue()
        self.assertEqual(len(line.strip().splitlines()), 1, line)
        self.assertIn("scenario 'hexagn': no such file, and no hexagn.yaml in ", line)
        self.assertIn(os.path.realpath(CONFIG), [os.path.realpath(p) for p in line.split(" in ", 1)[1].strip().split(", ")])

    def test_every_tool_takes_a_name(self):
        def run(*cmd):
            return subprocess.run(cmd, capture_output=True, text=True, timeout=300, cwd=self.tmp,
                                  env=dict(self.env, MPLCONFIGDIR=self.tmp))
        info = run("rosrun", PKG, "scenario_info", "--scenario", "hexagon")
        self.assertEqual((info.returncode, info.stdout), (0, "agents 6\n"), info.stderr)
        bad = run("rosrun", PKG, "scenario_info", "--scenario", "hexagn")
        self.assertEqual(bad.returncode, 2)
        self.assertTrue(bad.stderr.startswith("scenario_info: error: scenario 'hexagn': no such file"), bad.stderr)
        roa = run("rosrun", PKG, "roa", "--scenario", "hexagon", "--agent", "1", "--x-range", "-1", "1", "--y-range",
                  "-1", "1", "--resolution", "2", "2", "--steps", "10", "--out", "roa.csv")
        self.assertEqual(roa.returncode, 0, roa.stderr)
        margin = run("rosrun", PKG, "delay_margin", "--scenario", "square", "--delays", "0", "1", "--runs", "1",
                     "--steps", "20", "--losses", "0", "--out-dir", self.tmp)
        self.assertEqual(margin.returncode, 0, margin.stderr)
        plot = run("/usr/bin/python3", os.path.join(SOURCE, "scripts", "plot_roa.py"), "--roa", "roa.csv",
                   "--scenario", "hexagon", "--agent", "1", "--out", "roa.png")
        self.assertEqual(plot.returncode, 0, plot.stderr)
        where = run("rosrun", "--prefix", "echo", PKG, "simulate")  # the path rosrun would run
        self.assertEqual(where.returncode, 0, where.stderr)
        simulate = where.stdout.strip()
        euler = run("/usr/bin/python3", os.path.join(SOURCE, "scripts", "euler_comparison.py"), "--scenario", "square",
                    "--duration", "0.1", "--out-dir", "euler", "--simulate", simulate)
        self.assertEqual(euler.returncode, 0, euler.stderr)
        self.assertTrue(os.path.isfile(os.path.join(self.tmp, "euler", "euler_comparison.png")))
        # A manoeuvre scenario by name: simulate and plot_simulation, which also reads its schedule.
        sim = run("rosrun", PKG, "simulate", "--scenario", "hexagon_manoeuvre", "--steps", "40", "--out", "m.csv",
                  "--metrics", "mm.csv")
        self.assertEqual(sim.returncode, 0, sim.stderr)
        plot = run("/usr/bin/python3", os.path.join(SOURCE, "scripts", "plot_simulation.py"), "--scenario",
                   "hexagon_manoeuvre", "--traj", "m.csv", "--metrics", "mm.csv", "--out-dir", "sim")
        self.assertEqual(plot.returncode, 0, plot.stderr)
        self.assertTrue(os.path.isfile(os.path.join(self.tmp, "sim", "hexagon_manoeuvre_manoeuvre.png")))


if __name__ == "__main__":
    import rosunit
    rosunit.unitrun(PKG, "scenario_names", ScenarioNames)
