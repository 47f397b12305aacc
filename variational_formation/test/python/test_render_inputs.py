"""render_bag.py's reading of a robots bag (robots.launch record:=true), without a display: a
bag written here the way rosbag record receives such a run, on wall time: the robots publish for
2 s before the run's first step and 1 s after its last, the run's steps come 1 % late (wall
timers under load), and a burst of 20 steps reaches the bag 0.5 s late.

- The part it replays (variational_formation/run_clock.py) runs from the markers of the run's
  first shown step to those of its last, on the run's own clock: each message at the run's time
  of its stamp, so that the video's time is the run's time (the status's t_k = k h), whatever
  the bag's time; --from/--to count the run's time. The copy holds the first and the last shown
  steps' markers, whatever the rounding of their stamps in seconds and the order of reception.
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
from variational_formation_msgs.msg import FormationStatus
from visualization_msgs.msg import Marker, MarkerArray

from vf_harness import REPO, TempDirTestCase

T0 = 1764100000.0  # the recording's start, wall time [s]
SETUP, TAIL = 2.0, 1.0  # [s] recorded before the run's step 0 and after its last step
H, STEPS = 0.05, 100  # the run: 5 s of its own time
STRETCH = 1.01  # wall time per run time: the ticks come late
BURST, BURST_DELAY = range(40, 60), 0.5  # steps whose messages reach the bag late, at once [s]
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


def step_stamp(k):
    return rospy.Time.from_sec(T0 + SETUP + k * H * STRETCH)


def received(k, after):
    """When rosbag record gets a message of step k published `after` seconds after its stamp."""
    if k in BURST:
        return step_stamp(BURST[-1]) + rospy.Duration.from_sec(BURST_DELAY)
    return step_stamp(k) + rospy.Duration.from_sec(after)


def write_robots_bag(path):
    """Robots' tf at 50 Hz over the whole recording; from step 0 on, the agents' tf and the
    monitor's status and markers every step, stamped when published. rosbag record receives the
    status 3 ms and the markers 1 ms after publishing, except at step 0, the other way round (two
    connections, either order), and the burst's 0.5 s after its last step."""
    with rosbag.Bag(path, "w") as bag:
        for k in range(int((SETUP + STEPS * H * STRETCH + TAIL) * 50) + 1):
            now = rospy.Time.from_sec(T0 + k * 0.02)
            bag.write("/tf", TFMessage([transform(now, "world", f"formation/robot_{i}/base_link", 2.0 * i)
                                        for i in range(ROBOTS)]), now)
        for k in range(STEPS + 1):
            status = FormationStatus(step=k, time=k * H)
            status.header.stamp, status.header.frame_id = step_stamp(k), "world"
            bag.write("/formation/status", status, received(k, 0.001 if k == 0 else 0.003))
            sphere = Marker(ns="agents", type=Marker.SPHERE_LIST, text=str(k))
            sphere.header = status.header
            sphere.scale.x = sphere.scale.y = sphere.scale.z = 0.2
            bag.write("/formation/markers", MarkerArray([sphere]), received(k, 0.003 if k == 0 else 0.001))
            bag.write("/tf", TFMessage([transform(step_stamp(k), "world", f"formation/agent_{i}", 2.0 * i)
                                        for i in range(ROBOTS)]), received(k, 0.002))


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
        self.assertGreater(self.contents.end - self.contents.start, STEPS * H * STRETCH + SETUP + TAIL - 0.021)
        run = self.span()
        self.assertTrue(run.on_wall_time)
        self.assertEqual((run.start, run.end), (0.0, STEPS * H))
        # The replay's bag time is the run's: the video lasts the run's time over the speed.
        self.assertAlmostEqual(run.first, 0.0, delta=2e-6)
        self.assertAlmostEqual(run.last, STEPS * H, delta=2e-6)

    def test_the_copy_is_on_the_runs_clock(self):
        run = self.span()
        copy = self.path("run.bag")
        run.write_on_run_time(self.contents, ["/formation/markers", "/tf"], copy)
        markers, robots, times = {}, [], []
        with rosbag.Bag(copy) as bag:
            for topic, msg, t in bag.read_messages():
                times.append(t.to_sec())
                if topic == "/formation/markers":
                    markers[int(msg.markers[0].text)] = (t.to_sec(), msg.markers[0].header.stamp.to_sec())
                elif msg.transforms[0].child_frame_id.endswith("base_link"):
                    robots.append((t.to_sec(), msg.transforms[0].header.stamp.to_sec()))
        self.assertEqual(times, sorted(times))
        # Step k at t_k = k h, its time and stamp alike, the late burst too.
        self.assertEqual(sorted(markers), list(range(STEPS + 1)))
        for k, (t, stamp) in markers.items():
            self.assertAlmostEqual(t, k * H, delta=1e-6, msg=f"step {k}")
            self.assertAlmostEqual(stamp, k * H, delta=1e-6, msg=f"step {k}")
        # The robots' tf of the run only (none from before step 0 or after the last), at 50 Hz of
        # wall time, which is 50.5 Hz of the run's.
        self.assertEqual(len(robots), int(STEPS * H * STRETCH * 50) + 1)
        self.assertTrue(all(0.0 <= t <= STEPS * H and t == stamp for t, stamp in robots))

    def test_the_copy_holds_the_first_and_last_shown_steps(self):
        # At this epoch a stamp in seconds is rounded to 0.24 us, differently from its
        # nanoseconds times 1e-9 for about half the steps: the copy compares the stamps exactly.
        # From k = 10 on, --to falls after the burst (steps 40 to 59 received after step 60).
        for k in range(40):
            with self.subTest(first_step=k):
                run = self.span(k * H, (k + 50) * H)
                copy = self.path(f"run{k}.bag")
                run.write_on_run_time(self.contents, ["/formation/markers"], copy)
                with rosbag.Bag(copy) as bag:
                    shown = [(int(msg.markers[0].text), t.to_sec()) for _, msg, t in bag.read_messages()]
                self.assertEqual([step for step, _ in shown], list(range(k, k + 51)))
                # The bag's times are whole nanoseconds (rospy rounds down).
                self.assertAlmostEqual(shown[0][1], run.start, delta=2e-9)
                self.assertAlmostEqual(shown[-1][1], run.end, delta=2e-9)

    def test_from_and_to_count_the_runs_time(self):
        run = self.span(1.0, 2.5)
        self.assertEqual((run.start, run.end), (1.0, 2.5))
        self.assertAlmostEqual(run.last - run.first, 1.5, delta=3e-6)
        self.assertAlmostEqual(run.first_stamp, step_stamp(20).to_sec(), delta=1e-6)
        self.assertAlmostEqual(run.last_stamp, step_stamp(50).to_sec(), delta=1e-6)

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

    def test_the_worlds_markers_are_shown_where_the_bag_has_them(self):
        # robots.launch world:=mujoco records /formation/world/markers: the display World shows
        # them (a team's topic below its namespace); a bag without them has no such display.
        scene = self.render.Scene(self.contents, "/formation/markers", self.contents.start, self.contents.end)
        args = argparse.Namespace(fps=25, width=640, height=480, camera="fit")
        template = os.path.join(REPO, "config", "formation.rviz")

        def marker_displays(world):
            config = yaml.safe_load(self.render.rviz_config(template, "/team_a/formation/markers", [], scene, args,
                                                            world))
            return {d["Name"]: d["Marker Topic"] for d in config["Visualization Manager"]["Displays"]
                    if d["Class"] == "rviz/MarkerArray"}

        self.assertEqual(marker_displays("/team_a/formation/world/markers"),
                         {"World": "/team_a/formation/world/markers", "Formation": "/team_a/formation/markers"})
        self.assertEqual(marker_displays(None), {"Formation": "/team_a/formation/markers"})
