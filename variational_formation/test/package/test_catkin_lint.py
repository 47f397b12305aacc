"""catkin_lint -W2 on the repository's three packages reports nothing: no error, no warning and no notice beyond
those CMakeLists.txt tells it to ignore, each with the reason beside the pragma."""
import os
import shutil
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from vf_harness import REPO, run  # noqa: E402


class CatkinLintTest(unittest.TestCase):
    def test_clean_at_level_2(self):
        self.assertIsNotNone(shutil.which("catkin_lint"), "catkin_lint is not installed (Debian: catkin-lint)")
        # Each package by its folder in the repository (the workspace's links would list them twice).
        root = os.path.dirname(REPO)
        packages = [os.path.join(root, name) for name in
                    ("variational_formation", "variational_formation_core", "variational_formation_msgs")]
        result = run(["catkin_lint", "-W2", *packages])
        problems = [line for line in result.stdout.splitlines() + result.stderr.splitlines()
                    if ": error:" in line or ": warning:" in line or ": notice:" in line]
        self.assertEqual(problems, [], result.stdout + result.stderr)
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        self.assertIn("checked 3 packages", result.stdout + result.stderr)


if __name__ == "__main__":
    unittest.main()
