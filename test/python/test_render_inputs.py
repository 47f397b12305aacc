"""render_bag.py's reading of a robots bag (robots.launch record:=true), without a display: a
bag written here the way rosbag record receives such a run, on wall time, with the robots
publishing for 2 s before the run's first step and 1 s after its last.

- The part it replays runs from the markers of the run's first shown step to those of its last
  (stamped like the steps' status), so that the video's time is the run's own time; --from/--to
  count the run's time.
- The rviz configuration it writes draws one name per robot: the agents' frames are named, the
  robots' base_link frames (on top of them) keep their axes but no name.
"""
import argparse
import importlib.util
import os

import rosbag
import rospy
import yaml
from geometry_msgs.msg import TransformStamped
from tf2_msgs.msg import TFMessage
from variational_formation.msg import FormationStatus
from visualization_msgs.msg import Marker, MarkerArray

from vf_harness import REPO, TempDirTestCase

T0 = 1764100000.0  # the recording's start, wall time [s]
SETUP, TAIL = 2.0, 1.0  # [s] recorded before the run's step 0 and after its last step
H, STEPS = 0.05, 100  # the run: 5 s
ROBOTS = 3


def render_bag():
    spec = importlib.util.spec_from_file_location("render_bag", os.path.join(REPO, "scripts", "render_bag.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def transform(stamp, parent, child, x):
    t = TransformStamped()
    t.header.stamp, t.header.frame_id, t.child_frame_id = stamp, parent, child
    t.transform.translation.x, t.transform.rotation.w = x, 1.0
    return t


def write_robots_bag(path):
    """Robots' tf at 50 Hz over the whole recording; from step 0 on, the agents' tf and the
    monitor's status and markers every step, stamped when published. rosbag record receives the
    status 3 ms and the markers 1 ms after publishing, except step 0's markers, which come 1 ms
    before the status (two connections, either order)."""
    with rosbag.Bag(path, "w") as bag:
        for k in range(int((SETUP + STEPS * H + TAIL) * 50) + 1):
            now = rospy.Time.from_sec(T0 + k * 0.02)
            bag.write("/tf", TFMessage([transform(now, "world", f"formation/robot_{i}/base_link", 2.0 * i)
                                        for i in range(ROBOTS)]), now)
        for k in range(STEPS + 1):
            stamp = rospy.Time.from_sec(T0 + SETUP + k * H)
            status = FormationStatus(step=k, time=k * H)
            status.header.stamp, status.header.frame_id = stamp, "world"
            bag.write("/formation/status", status, stamp + rospy.Duration.from_sec(0.003))
            sphere = Marker(ns="agents", type=Marker.SPHERE_LIST)
            sphere.header = status.header
            sphere.scale.x = sphere.scale.y = sphere.scale.z = 0.2
            bag.write("/formation/markers", MarkerArray([sphere]),
                      stamp + rospy.Duration.from_sec(-0.001 if k == 0 else 0.001))
            bag.write("/tf", TFMessage([transform(stamp, "world", f"formation/agent_{i}", 2.0 * i)
                                        for i in range(ROBOTS)]), stamp + rospy.Duration.from_sec(0.002))


class RobotsBagTest(TempDirTestCase):
    def setUp(self):
        super().setUp()
        self.render = render_bag()
        self.bag = self.path("hexagon.bag")
        write_robots_bag(self.bag)
        self.contents = self.render.BagContents([self.bag])

    def span(self, start=0.0, end=None):
        return self.render.RunSpan(self.contents, "/formation/status", "/formation/markers", start, end)

    def test_the_replay_is_the_run(self):
        self.assertAlmostEqual(self.contents.end - self.contents.start, SETUP + STEPS * H + TAIL, delta=0.021)
        run = self.span()
        # From step 0's markers to the last step's.
        self.assertAlmostEqual(run.first, T0 + SETUP - 0.001, delta=1e-5)
        self.assertAlmostEqual(run.last, T0 + SETUP + STEPS * H + 0.001, delta=1e-5)
        self.assertAlmostEqual(run.last - run.first, STEPS * H, delta=0.005)  # the video's length at speed 1
        self.assertEqual((run.start, run.end), (0.0, STEPS * H))

    def test_from_and_to_count_the_runs_time(self):
        run = self.span(1.0, 2.5)
        self.assertAlmostEqual(run.start, 1.0, delta=1e-9)
        self.assertAlmostEqual(run.end, 2.5, delta=1e-9)
        self.assertAlmostEqual(run.first, T0 + SETUP + 1.0 + 0.001, delta=1e-5)
        self.assertAlmostEqual(run.last, T0 + SETUP + 2.5 + 0.001, delta=1e-5)

    def test_from_beyond_the_run(self):
        with self.assertRaises(SystemExit) as stop:
            self.span(STEPS * H + 0.5)
        self.assertEqual(stop.exception.code, 2)

    def test_one_name_per_robot(self):
        scene = self.render.Scene(self.contents, "/formation/markers", self.contents.start, self.contents.end)
        args = argparse.Namespace(fps=25, width=640, height=480, camera="fit")
        config = yaml.safe_load(self.render.rviz_config(os.path.join(REPO, "config", "formation.rviz"),
                                                        "/formation/markers", [], scene, args))
        agents = [f"formation/agent_{i}" for i in range(ROBOTS)]
        robots = [f"formation/robot_{i}/base_link" for i in range(ROBOTS)]
        named, axes = [], []  # frames drawn with a name / with axes, once per display
        for display in config["Visualization Manager"]["Displays"]:
            if display["Class"] != "rviz/TF" or not display.get("Enabled", True):
                continue
            frames = display.get("Frames", {})
            shown = [f for f in agents + robots + ["world"]
                     if frames.get(f, {}).get("Value", frames.get("All Enabled", True))]
            named += shown if display.get("Show Names") else []
            axes += shown if display.get("Show Axes") else []
        self.assertEqual(sorted(named), sorted(agents + ["world"]), "the frames whose names are drawn")
        self.assertEqual(sorted(axes), sorted(agents + robots + ["world"]), "the frames whose axes are drawn")
