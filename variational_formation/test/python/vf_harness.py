"""Shared harness of the Python tests (test/python, test/package): where things are, running a
script or tool on small inputs in a temporary folder, and checks of the files they write.

The workspace is $VF_WS (default .ws in the repository), as in scripts/common.sh; the tests run
after the build, so the tools are in its devel space."""
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
WS = os.environ.get("VF_WS") or os.path.join(os.path.dirname(REPO), ".ws")
DEVEL_BIN = os.path.join(WS, "devel", "lib", "variational_formation")
PYTHON = "/usr/bin/python3"
sys.path.insert(0, os.path.join(REPO, "src"))


def tool(name):
    """Path of a built C++ tool (simulate, roa, ...) in the devel space."""
    return os.path.join(DEVEL_BIN, name)


def script(name):
    return os.path.join(REPO, "scripts", name)


def run(command, cwd=None, env=None, timeout=300):
    """Runs a command, capturing text output; never raises on a non-zero exit."""
    return subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)


def png_size(path):
    """(width, height) of a PNG file, from its header; fails the caller's assertion if not a PNG."""
    with open(path, "rb") as f:
        head = f.read(24)
    if len(head) < 24 or head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        raise AssertionError(f"{path} is not a PNG file")
    return struct.unpack(">II", head[16:24])


class TempDirTestCase(unittest.TestCase):
    """A test with its own temporary folder, self.tmp, removed afterwards."""

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="vf_test_")
        self.addCleanup(shutil.rmtree, self.tmp, ignore_errors=True)

    def path(self, *parts):
        return os.path.join(self.tmp, *parts)

    def run_script(self, name, *args, **kwargs):
        """Runs scripts/<name> with /usr/bin/python3 in self.tmp (matplotlib's cache there too)."""
        env = dict(os.environ, MPLCONFIGDIR=self.path(".matplotlib"), PYTHONDONTWRITEBYTECODE="1")
        return run([PYTHON, script(name)] + [str(a) for a in args], cwd=self.tmp, env=env, **kwargs)

    def assertSucceeded(self, result):
        self.assertEqual(result.returncode, 0, f"exit {result.returncode}\nstdout: {result.stdout}\n"
                                                f"stderr: {result.stderr}")

    def assertBadInput(self, result, *words):
        """Exit status 2 and one line on stderr containing each of `words` (no traceback)."""
        self.assertEqual(result.returncode, 2, f"stdout: {result.stdout}\nstderr: {result.stderr}")
        lines = result.stderr.strip().splitlines()
        self.assertEqual(len(lines), 1, f"expected one error line, got: {result.stderr}")
        for word in words:
            self.assertIn(word, lines[0])

    def assertPng(self, path, min_width=200, min_height=150):
        """`path` is a PNG of at least that size (pixels)."""
        self.assertTrue(os.path.isfile(path), f"{path} was not written")
        width, height = png_size(path)
        self.assertGreaterEqual(width, min_width, path)
        self.assertGreaterEqual(height, min_height, path)

    def simulate(self, scenario, *flags, name="run"):
        """simulate's traj.csv and metrics.csv of `scenario` in self.tmp: (traj, metrics)."""
        traj, metrics = self.path(f"{name}_traj.csv"), self.path(f"{name}_metrics.csv")
        self.assertSucceeded(run([tool("simulate"), "--scenario", scenario, "--out", traj, "--metrics", metrics]
                                 + [str(f) for f in flags]))
        return traj, metrics
