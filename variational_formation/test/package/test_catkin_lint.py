"""catkin_lint -W2 on the package reports nothing: no error, no warning and no notice beyond
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
        # The checkout's folder name is not the package's (a worktree, a CI checkout): not a
        # property of the package.
        result = run(["catkin_lint", "-W2", "--ignore", "package_path_name", REPO])
        problems = [line for line in result.stdout.splitlines() + result.stderr.splitlines()
                    if ": error:" in line or ": warning:" in line or ": notice:" in line]
        self.assertEqual(problems, [], result.stdout + result.stderr)
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)


if __name__ == "__main__":
    unittest.main()
