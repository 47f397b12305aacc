"""Generated launch files do not pile up in ROS_HOME/variational_formation: the same scenario
and arguments give the same file, other arguments another one (roslaunch --nodes parses the
launch, which writes the file, without a master)."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from vf_harness import TempDirTestCase, run  # noqa: E402


class GeneratedLaunchFilesTest(TempDirTestCase):
    def nodes(self, launch, *args):
        env = dict(os.environ, ROS_HOME=self.path("ros_home"))
        result = run(["roslaunch", "--nodes", "variational_formation", launch] + list(args), env=env)
        self.assertSucceeded(result)
        return result.stdout.split()

    def written(self):
        folder = self.path("ros_home", "variational_formation")
        return sorted(os.listdir(folder)) if os.path.isdir(folder) else []

    def test_same_arguments_same_file(self):
        first = self.nodes("formation.launch", "scenario:=hexagon")
        self.assertIn("/formation/agent_5", first)
        self.assertEqual(len(self.written()), 1)
        self.assertEqual(self.nodes("formation.launch", "scenario:=hexagon"), first)
        self.assertEqual(len(self.written()), 1)
        self.nodes("formation.launch", "scenario:=hexagon", "order:=reverse")
        self.assertEqual(len(self.written()), 2)
        self.nodes("robots.launch", "scenario:=hexagon")
        self.nodes("robots.launch", "scenario:=hexagon")
        names = self.written()
        self.assertEqual(len(names), 3, names)
        self.assertTrue(all(n.startswith("hexagon_") and n.endswith(".launch") for n in names), names)
