#!/usr/bin/python3
"""rostest (two_teams.test): formations side by side with the defaults, and how a launch ends.

- The fixture (two_teams.launch: the hexagon under /team_a, the tetrahedron under /team_b, one
  output_dir): both runs succeed, and each bag, named after its namespace, is complete and
  equals simulate bit for bit.
- The same file run by roslaunch (under /side_a and /side_b): roslaunch ends by itself, status
  0, only once both runs are over (both results say succeeded, though the hexagon is over long
  before the tetrahedron), and prints no red line and no "REQUIRED process ... has died".
- A second run into the same output_dir says in one line which result and bag it replaces.
- A bad argument is one line from roslaunch, status 2, with no RLException dump.
- `roslaunch formation.launch --ros-args` lists no required argument.
"""
import os
import shutil
import signal
import subprocess
import sys
import unittest

import rospy
import rostest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402

PKG = vf_rostest.PKG
TEAMS = {"team_a": "hexagon", "team_b": "tetrahedron"}
RED = "\x1b[31m"


def roslaunch(*args, timeout=120):
    """roslaunch on the test's master: (exit status, everything it printed). One that has not
    ended by itself within `timeout` is stopped with SIGINT: status None."""
    launch = subprocess.Popen(["roslaunch", *args], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              start_new_session=True)
    try:
        out, _ = launch.communicate(timeout=timeout)
        return launch.returncode, out
    except subprocess.TimeoutExpired:
        os.killpg(launch.pid, signal.SIGINT)
        out, _ = launch.communicate(timeout=60)
        return None, out + f"\n(did not end by itself within {timeout} s)"


def result(path):
    return vf_rostest.wait_for_result(path, 0.0).get("result")


@vf_rostest.reported_setup
class TwoTeams(unittest.TestCase, vf_rostest.RunChecks):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("two_teams_test")
        cls.out = rospy.get_param("~output_dir")
        cls.results = {team: vf_rostest.wait_for_result(os.path.join(cls.out, f"{team}_{name}.result.yaml"), 200.0)
                       for team, name in TEAMS.items()}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.out, ignore_errors=True)

    def check_team(self, team):
        name = TEAMS[team]
        self.assertEqual(self.results[team].get("result"), "succeeded", f"{team}: {self.results[team]}")
        path = vf_rostest.scenario_path(name)
        ns = f"/{team}/formation"
        rec = vf_rostest.Recording(os.path.join(self.out, f"{team}_{name}.bag"), ns=ns)
        self.check_recording(rec, vf_rostest.load_scenario(path), vf_rostest.simulate(path), ns=ns)
        self.assertFalse([f for f in rec.tf if not f.startswith(f"{team}/formation/")], "foreign tf frames")

    def test_team_a_hexagon(self):
        self.check_team("team_a")

    def test_team_b_tetrahedron(self):
        self.check_team("team_b")

    def test_only_namespaced_files(self):
        files = [f for f in os.listdir(self.out) if os.path.isfile(os.path.join(self.out, f))]
        self.assertEqual(sorted(files),
                         sorted(f"{t}_{n}{ext}" for t, n in TEAMS.items() for ext in (".bag", ".result.yaml")))

    def test_roslaunch_ends_once_both_are_over_without_red(self):
        out = os.path.join(self.out, "launched")
        launch = os.path.join(os.path.dirname(os.path.abspath(__file__)), "two_teams.launch")
        status, log = roslaunch(launch, f"output_dir:={out}", "record:=false", "team_a:=side_a", "team_b:=side_b")
        self.assertEqual(status, 0, log[-6000:])
        for side, name in (("side_a", "hexagon"), ("side_b", "tetrahedron")):
            self.assertEqual(result(os.path.join(out, f"{side}_{name}.result.yaml")), "succeeded", log[-3000:])
        self.assertNotIn("REQUIRED process", log)
        self.assertEqual([line for line in log.splitlines() if RED in line], [])
        self.assertIn("shutting down processing monitor complete", log)

    def test_a_second_run_names_what_it_replaces(self):
        out = os.path.join(self.out, "twice")
        args = ["variational_formation", "formation.launch", "scenario:=free_particle", "record:=true",
                f"output_dir:={out}"]
        for run in range(2):
            status, log = roslaunch(*args)
            self.assertEqual(status, 0, log[-3000:])
            self.assertEqual(result(os.path.join(out, "free_particle.result.yaml")), "succeeded", log[-3000:])
            self.assertEqual([line for line in log.splitlines() if RED in line], [])
        replacing = [line for line in log.splitlines() if "replacing" in line]
        self.assertEqual(len(replacing), 2, log[-3000:])
        self.assertIn(os.path.join(out, "free_particle.result.yaml"), replacing[0] + replacing[1])
        self.assertIn(os.path.join(out, "free_particle.bag"), replacing[0] + replacing[1])

    def test_bad_argument_is_one_line(self):
        status, log = roslaunch(PKG, "formation.launch", "scenario:=hexagon", "order:=sideways", timeout=60)
        self.assertEqual(status, 2, log)
        errors = [line for line in log.splitlines() if "error" in line.lower() or "exception" in line.lower()]
        self.assertEqual(errors, ["make_agents_launch: error: order: invalid choice: 'sideways' "
                                  "(choose from 'forward', 'reverse')"], log)

    def test_ros_args_lists_no_required_argument(self):
        run = subprocess.run(["roslaunch", PKG, "formation.launch", "--ros-args"], capture_output=True, text=True,
                             timeout=60)
        self.assertEqual(run.returncode, 0, run.stderr)
        self.assertNotIn("Required Arguments", run.stdout)
        self.assertIn('agent_manager (default "auto")', run.stdout)


if __name__ == "__main__":
    rostest.rosrun(PKG, "two_teams_test", TwoTeams, sys.argv)
