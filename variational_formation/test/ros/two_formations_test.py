#!/usr/bin/python3
"""rostest (two_formations.test): two hexagons run side by side under /team_a and /team_b. Both
succeed, each bag holds its own formation's names and tf frames only, complete and equal to
simulate bit for bit."""
import os
import shutil
import sys
import unittest

import rospy
import rostest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402


@vf_rostest.reported_setup
class TwoFormations(unittest.TestCase, vf_rostest.RunChecks):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("two_formations_test")
        cls.out = rospy.get_param("~output_dir")
        cls.path = vf_rostest.scenario_path("hexagon")
        cls.scenario = vf_rostest.load_scenario(cls.path)
        cls.results = {team: vf_rostest.wait_for_result(os.path.join(cls.out, team, f"{team}_hexagon.result.yaml"), 120.0)
                       for team in ("team_a", "team_b")}
        cls.expected = vf_rostest.simulate(cls.path)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.out, ignore_errors=True)

    def check_team(self, team, other):
        self.assertEqual(self.results[team].get("result"), "succeeded", f"{team}: {self.results[team]}")
        ns = f"/{team}/formation"
        rec = vf_rostest.Recording(os.path.join(self.out, team, f"{team}_hexagon.bag"), ns=ns)
        self.check_recording(rec, self.scenario, self.expected, ns=ns)
        self.assertFalse([t for t in rec.topics if t.startswith(f"/{other}/")], "the other team's topics")
        self.assertFalse([f for f in rec.tf if not f.startswith(f"{team}/formation/")], "foreign tf frames")

    def test_team_a(self):
        self.check_team("team_a", "team_b")

    def test_team_b(self):
        self.check_team("team_b", "team_a")


if __name__ == "__main__":
    rostest.rosrun(vf_rostest.PKG, "two_formations_test", TwoFormations, sys.argv)
