#!/usr/bin/python3
"""rostest: whole launches, run as a user would (roslaunch in a subprocess, on the test's master).

- The recorded bag holds every step of every agent, status, markers and tf, with no gap and no
  duplicate.
- A bad scenario makes the nodes exit non-zero with a one-line error naming the field.
- A bad launch argument ends the launch with a one-line error naming it.
- A bad node parameter is one ROS_FATAL line naming it and exit status 2.
- The recorded bag, replayed into rviz under Xvfb with the shipped config, renders the agents:
  the screenshot contains the agent marker colours.
"""
import colorsys
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

import matplotlib

matplotlib.use("Agg")
import matplotlib.image  # noqa: E402
import numpy as np  # noqa: E402
import rosbag  # noqa: E402
import rospkg  # noqa: E402
import rostest  # noqa: E402
import yaml  # noqa: E402

PKG = "variational_formation"
SCENARIO = "hexagon"
# Agent colours of src/ros/markers.cpp (agentColour), for the agents of the hexagon.
PALETTE = [(0.90, 0.10, 0.10), (0.10, 0.45, 0.90), (0.10, 0.75, 0.20), (0.95, 0.60, 0.05),
           (0.60, 0.20, 0.80), (0.05, 0.80, 0.80)]


def launch(*args, timeout=180):
    return subprocess.run(["roslaunch", PKG, "formation.launch", *args], capture_output=True,
                          text=True, timeout=timeout)


class LaunchTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="vf_launch_test_")
        cls.pkg = rospkg.RosPack().get_path(PKG)
        with open(os.path.join(cls.pkg, "config", SCENARIO + ".yaml")) as f:
            cls.scenario = yaml.safe_load(f)
        cls.recording = launch(f"scenario:={SCENARIO}", "record:=true", f"output_dir:={cls.tmp}")
        cls.bag = os.path.join(cls.tmp, SCENARIO + ".bag")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_bag_holds_every_step_once(self):
        self.assertEqual(self.recording.returncode, 0, self.recording.stderr[-2000:])
        n, steps = len(self.scenario["agents"]), int(self.scenario["steps"])
        states = {i: [] for i in range(n)}
        status, markers, tf = [], 0, {i: 0 for i in range(n)}
        with rosbag.Bag(self.bag) as bag:
            for topic, msg, _ in bag.read_messages():
                if topic.endswith("/state"):
                    states[msg.id].append(msg.step)
                    self.assertEqual(topic, f"/formation/agent_{msg.id}/state")
                elif topic == "/formation/status":
                    status.append(msg.step)
                elif topic == "/formation/markers":
                    markers += 1
                elif topic == "/tf":
                    for t in msg.transforms:
                        self.assertEqual(t.header.frame_id, "world")
                        tf[int(t.child_frame_id.split("_")[1])] += 1
        expected = list(range(steps + 1))
        for i in range(n):
            self.assertEqual(states[i], expected, f"agent {i}")
            self.assertEqual(tf[i], steps + 1, f"tf of agent {i}")
        self.assertEqual(status, expected)
        self.assertEqual(markers, steps + 1)

    def test_bad_scenario_fails_naming_the_field(self):
        bad = dict(self.scenario)
        bad["edges"] = list(self.scenario["edges"]) + [[0, 9]]
        path = os.path.join(self.tmp, "bad.yaml")
        with open(path, "w") as f:
            yaml.safe_dump(bad, f)
        run = launch(f"scenario:={path}", timeout=60)
        out = run.stdout + run.stderr
        errors = [line for line in out.splitlines() if "agent 9 does not exist" in line]
        self.assertTrue(errors, out[-3000:])
        for line in errors:
            self.assertIn("edges[9]", line)
        self.assertIn("exit code 2", out)  # roslaunch reports the nodes' status

    def test_bad_launch_argument_ends_the_launch(self):
        # The spawner is required: its one-line error ends the launch (launch() times out if not).
        for arg, words in (("order:=sideways", "argument --order"), ("rate:=-1", "--rate and --stagger")):
            run = launch(f"scenario:={SCENARIO}", arg, timeout=60)
            out = run.stdout + run.stderr
            errors = [line for line in out.splitlines() if line.startswith("spawn_agents: error:")]
            self.assertEqual(len(errors), 1, out[-3000:])
            self.assertIn(words, errors[0])

    def test_bad_node_parameters_are_one_fatal_line(self):
        scenario = os.path.join(self.pkg, "config", SCENARIO + ".yaml")
        cases = (("monitor", ["_trail_length:=abc"], "~trail_length: expected an integer"),
                 ("monitor", ["_trail_length:=1"], "~trail_length: must be >= 2"),
                 ("agent", ["_id:=1", "_real_time_factor:=fast"], "~real_time_factor: expected a number"),
                 ("agent", ["_id:=99"], "id: must be an agent id 0..5, got 99"),
                 ("agent", [], "~id: required parameter missing"))
        for k, (node, params, words) in enumerate(cases):
            # A fresh node name each time: private parameters stay on the master after a run.
            run = subprocess.run(["rosrun", PKG, node, f"__name:=param_probe_{k}", f"_scenario:={scenario}",
                                  *params], capture_output=True, text=True, timeout=30)
            fatal = [line for line in (run.stdout + run.stderr).splitlines() if "FATAL" in line]
            self.assertEqual(run.returncode, 2, f"{node} {params}: {run.stdout[-1000:]}{run.stderr[-1000:]}")
            self.assertEqual(len(fatal), 1, f"{node} {params}")
            self.assertIn(words, fatal[0])

    def test_rviz_renders_the_recorded_bag(self):
        self.assertTrue(os.path.exists(self.bag))
        display = ":%d" % (90 + os.getpid() % 9)
        env = dict(os.environ, DISPLAY=display)
        procs = []
        try:
            procs.append(subprocess.Popen(["Xvfb", display, "-screen", "0", "1280x900x24"],
                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
            time.sleep(2)
            subprocess.run(["rosparam", "set", "/use_sim_time", "true"], check=True)
            procs.append(subprocess.Popen(["rviz", "-d", os.path.join(self.pkg, "config", "formation.rviz")],
                                          env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
            time.sleep(8)
            procs.append(subprocess.Popen(["rosbag", "play", "--clock", "-q", "-r", "0.5", self.bag],
                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
            time.sleep(8)
            dump = os.path.join(self.tmp, "shot.xwd")
            with open(dump, "wb") as f:
                subprocess.run(["xwd", "-root", "-silent", "-display", display], stdout=f, check=True)
            png = os.path.join(self.tmp, "rviz.png")
            subprocess.run(["rosrun", PKG, "xwd_to_png.py", dump, png], check=True)
            keep = os.environ.get("VF_SCREENSHOT")
            if keep:
                shutil.copy(png, keep)
        finally:
            for p in reversed(procs):
                p.terminate()
                try:
                    p.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    p.kill()
        image = matplotlib.image.imread(png)[:, :, :3]
        hsv = matplotlib.colors.rgb_to_hsv(image)
        for i, rgb in enumerate(PALETTE):
            hue = colorsys.rgb_to_hsv(*rgb)[0]
            distance = np.minimum(abs(hsv[:, :, 0] - hue), 1 - abs(hsv[:, :, 0] - hue))
            matches = (distance < 0.02) & (hsv[:, :, 1] > 0.5) & (hsv[:, :, 2] > 0.25)
            self.assertGreater(int(matches.sum()), 30, f"agent {i}'s colour {rgb} is not in the screenshot")


if __name__ == "__main__":
    rostest.rosrun(PKG, "launch_test", LaunchTest, sys.argv)
