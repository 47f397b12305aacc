"""Each script of scripts/ (except plot_bag.py and plot_simulation.py, tested beside their own
changes, and render_bag.py) run on a small input: the files it writes, and one bad input."""
import os
import socket
import struct
import xml.etree.ElementTree as ElementTree

import numpy as np

from vf_harness import REPO, TempDirTestCase, run, script, tool

HEXAGON = os.path.join(REPO, "config", "hexagon.yaml")
SQUARE = os.path.join(REPO, "config", "square.yaml")


class PlotDelayMarginTest(TempDirTestCase):
    def test_heatmap_of_a_small_campaign(self):
        self.assertSucceeded(run([tool("delay_margin"), "--scenario", HEXAGON, "--out-dir", self.tmp, "--kappa", "4",
                                  "--delays", "0", "3", "--losses", "0,0.2", "--runs", "2", "--steps", "300"]))
        summary = self.path("hexagon_delay_margin.csv")
        result = self.run_script("plot_delay_margin.py", "--summary", summary, "--out", self.path("dm.png"))
        self.assertSucceeded(result)
        self.assertIn("wrote", result.stdout)
        self.assertPng(self.path("dm.png"))

    def test_wrong_file_is_one_line(self):
        with open(self.path("x.csv"), "w") as f:
            f.write("a,b\n1,2\n")
        self.assertBadInput(self.run_script("plot_delay_margin.py", "--summary", self.path("x.csv"),
                                            "--out", self.path("dm.png")), "expected header")
        self.assertFalse(os.path.exists(self.path("dm.png")))


class PlotRoaTest(TempDirTestCase):
    def test_heatmap_of_a_small_grid(self):
        roa = self.path("roa.csv")
        self.assertSucceeded(run([tool("roa"), "--scenario", HEXAGON, "--agent", "1", "--x-range", "-4", "4",
                                  "--y-range", "-4", "4", "--resolution", "6", "5", "--steps", "100", "--out", roa]))
        result = self.run_script("plot_roa.py", "--roa", roa, "--scenario", HEXAGON, "--agent", "1",
                                 "--out", self.path("roa.png"))
        self.assertSucceeded(result)
        self.assertPng(self.path("roa.png"))

    def test_agent_out_of_range(self):
        roa = self.path("roa.csv")
        self.assertSucceeded(run([tool("roa"), "--scenario", HEXAGON, "--agent", "1", "--x-range", "-1", "1",
                                  "--y-range", "-1", "1", "--resolution", "2", "2", "--steps", "10", "--out", roa]))
        self.assertBadInput(self.run_script("plot_roa.py", "--roa", roa, "--scenario", HEXAGON, "--agent", "6",
                                            "--out", self.path("roa.png")), "--agent", "0..5")


class EulerComparisonTest(TempDirTestCase):
    def test_short_comparison_on_the_square(self):
        result = self.run_script("euler_comparison.py", "--scenario", SQUARE, "--duration", "0.5",
                                 "--out-dir", self.path("out"), "--simulate", tool("simulate"))
        self.assertSucceeded(result)
        self.assertPng(self.path("out", "euler_comparison.png"), 800, 500)
        rows = [line.split() for line in result.stdout.splitlines() if line.startswith(("variational", "explicit"))]
        # Two methods x three time steps, each with its state.
        self.assertEqual(len(rows), 6, result.stdout)
        for row in rows:
            self.assertTrue("bounded" in row or "DIVERGED" in row, row)

    def test_bad_duration(self):
        self.assertBadInput(self.run_script("euler_comparison.py", "--duration", "0", "--simulate", tool("simulate"),
                                            "--out-dir", self.tmp), "--duration")


class MakeAgentsLaunchTest(TempDirTestCase):
    def test_one_include_per_agent(self):
        out = self.path("agents.launch")
        result = self.run_script("make_agents_launch.py", "--scenario", HEXAGON, "--out", out, "--order", "reverse")
        self.assertSucceeded(result)
        self.assertEqual(result.stdout.strip(), out)
        includes = ElementTree.parse(out).getroot().findall("include")
        ids = [next(a.get("value") for a in inc.findall("arg") if a.get("name") == "id") for inc in includes]
        self.assertEqual(ids, ["5", "4", "3", "2", "1", "0"])
        # Written whole: no partial file left beside it.
        self.assertEqual([f for f in os.listdir(self.tmp) if f.endswith(".partial")], [])

    def test_bad_argument(self):
        self.assertBadInput(self.run_script("make_agents_launch.py", "--scenario", HEXAGON, "--out",
                                            self.path("a.launch"), "--loss", "2"), "loss", "probability")
        self.assertFalse(os.path.exists(self.path("a.launch")))

    def test_one_machines_share_in_a_named_manager(self):
        out = self.path("shard.launch")
        self.assertSucceeded(self.run_script("make_agents_launch.py", "--scenario", HEXAGON, "--out", out, "--nodelet",
                                             "true", "--ids", "4-5,1", "--manager-name", "manager_b",
                                             "--agent-manager", "manager_a manager_b"))
        nodes = ElementTree.parse(out).getroot().findall("node")
        self.assertEqual([n.get("name") for n in nodes], ["manager_b"])
        params = {p.get("name"): p.get("value") for p in nodes[0].findall("param")}
        self.assertEqual(params["agents"], "4 5 1")
        self.assertEqual(params["agent_manager"], "manager_a manager_b")

    def test_bad_share(self):
        launch = ("make_agents_launch.py", "--scenario", HEXAGON, "--out", self.path("a.launch"))
        self.assertBadInput(self.run_script(*launch, "--nodelet", "true", "--ids", "0-6"), "ids", "agent 6",
                            "6 agents")
        self.assertBadInput(self.run_script(*launch, "--nodelet", "true", "--ids", "3-1"), "ids", "empty range")
        self.assertBadInput(self.run_script(*launch, "--nodelet", "true", "--ids", "a"), "ids")
        self.assertBadInput(self.run_script(*launch, "--nodelet", "true", "--manager-name", "b/c"), "manager_name")
        self.assertBadInput(self.run_script(*launch, "--manager-name", "manager_b"), "only with nodelet true")
        self.assertFalse(os.path.exists(self.path("a.launch")))


class XwdToPngTest(TempDirTestCase):
    def write_xwd(self, path, pixels):
        """A 32-bit TrueColor XWD (version 7, MSB first) of an (h, w, 3) uint8 image."""
        height, width, _ = pixels.shape
        header = [100, 7, 2, 24, width, height, 0, 1, 32, 1, 32, 32, width * 4, 4, 0x00ff0000, 0x0000ff00,
                  0x000000ff, 8, 256, 0, width, height, 0, 0, 0]
        raw = (pixels[:, :, 0].astype(np.uint32) << 16) | (pixels[:, :, 1].astype(np.uint32) << 8) | pixels[:, :, 2]
        with open(path, "wb") as f:
            f.write(struct.pack(">25I", *header) + raw.astype(">u4").tobytes())

    def test_colours_survive(self):
        pixels = np.zeros((4, 5, 3), np.uint8)
        pixels[0, 0] = (255, 0, 0)
        pixels[3, 4] = (10, 200, 30)
        self.write_xwd(self.path("in.xwd"), pixels)
        self.assertSucceeded(self.run_script("xwd_to_png.py", self.path("in.xwd"), self.path("out.png")))
        import matplotlib.image
        image = (matplotlib.image.imread(self.path("out.png"))[:, :, :3] * 255).round().astype(np.uint8)
        np.testing.assert_array_equal(image, pixels)

    def test_not_an_xwd(self):
        with open(self.path("in.xwd"), "wb") as f:
            f.write(b"\0" * 10)
        self.assertBadInput(self.run_script("xwd_to_png.py", self.path("in.xwd"), self.path("out.png")), "too short")


class FailureReasonsTest(TempDirTestCase):
    def test_one_line_per_failure(self):
        os.makedirs(self.path("results", "pkg"))
        with open(self.path("results", "pkg", "r.xml"), "w") as f:
            f.write('<testsuite tests="2" failures="1" errors="0"><testcase name="good"/>'
                    '<testcase name="bad"><failure message="distance 0.3 &gt; 0.01\n  File &quot;x.py&quot;"/>'
                    '</testcase></testsuite>')
        result = self.run_script("failure_reasons.py", self.path("results"), "100")
        self.assertSucceeded(result)
        self.assertEqual(result.stdout.strip().splitlines(), ["r.xml: bad: distance 0.3 > 0.01"])


class RunFormationTest(TempDirTestCase):
    """run_formation.sh with launch:=robots runs robots.launch (its default scenario, the hexagon:
    300 steps at rate 1, 4.2 s), with formation.launch's result and exit status."""

    def run_formation(self, *args, timeout=180):
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{port}", ROS_HOME=self.path("ros_home"))
        return run(["bash", script("run_formation.sh"), "-p", str(port)] + list(args), env=env, timeout=timeout)

    def test_robots_launch_run_succeeds(self):
        result = self.run_formation("launch:=robots", f"output_dir:={self.tmp}")
        self.assertSucceeded(result)
        with open(self.path("hexagon.result.yaml")) as f:
            self.assertIn("result: succeeded", f.read())
        # robots.launch, not formation.launch, ran: it writes the robots' launch file.
        written = os.listdir(self.path("ros_home", "variational_formation"))
        self.assertTrue(any(n.startswith("hexagon_robots_") for n in written), written)
        self.assertIn("robot_sim", result.stdout)

    def test_robots_launch_that_cannot_start_fails(self):
        result = self.run_formation("launch:=robots", f"scenario:={self.path('missing.yaml')}",
                                    f"output_dir:={self.tmp}", timeout=60)
        self.assertNotEqual(result.returncode, 0, result.stdout)
        self.assertIn("run_formation: the run failed before the monitor started", result.stderr)

    def test_unknown_launch(self):
        self.assertBadInput(self.run_formation("launch:=agent"), "launch", "formation or robots", "'agent'")
