#!/usr/bin/python3
"""rostest (render.test): render_bag.py turns the hexagon's bag, recorded by formation.launch in
the same launch and split in parts (hexagon.bag, hexagon_1.bag, ...), into an MP4 and a GIF.
With the argument `robots` (render.test kind:=robots), the bag of robots.launch instead.

Checks, on both videos: ffprobe's duration is the run's (4.2 s) over the speed, within 10%, at
the asked size; no frame is blank; the last frame shows every agent's colour; the first and last
frames differ. A namespaced team's bag renders with --ns. No process the render started outlives
it, after a good run, after Ctrl-C, or after a failure. Bad inputs get one line on stderr and a
non-zero status: no bag, an empty bag, no ffmpeg on PATH, a display that cannot start (taken by
another X server), rviz that dies.

robots.launch's bag is on wall time and holds the robots' messages until after the run's last
step (here 1 s after it, as a launch ending at the run's end would), and from before its first
step or from the step at which rosbag record joined: its video is the run from the first
recorded step (within two steps) to the last, not the bag's length: frames 1/fps apart from 0 s,
the last at or after (4.2 s - that step's t) over the speed and the one before it before; 90 %
of the frames and the last one show every agent.

With `mujoco` (render.test kind:=mujoco), the bag of robots.launch world:=mujoco with unicycles:
the same checks, and the bag holds the world's markers at 20 Hz from when rosbag record joined them,
a body and a heading arrow per robot in each, every arrow from the robot's odometry position along
its heading (the same instant, to 1e-9), and the contact markers deleted (the hexagon's robots
never touch). The bodies are solid, the arrows on their tops reach out of the agents' spheres,
which are translucent halos round them (opacity 0.35), and the video's last frame shows the
bodies' solid colours (of the robots whose colour no other marker has).

VF_TEST_DISPLAY=:N (optional) makes every render use X display :N, and the busy-display case
N + 1; by default Xvfb picks free ones.

Private parameters:
  output_dir   where formation.launch writes the bag and the result file (removed after)
"""
import os
import re
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import unittest

import numpy as np
import roslib.packages
import rospy
import rostest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402

PKG = vf_rostest.PKG
RUN_SECONDS, STEP = 4.2, 0.014  # config/hexagon.yaml: 300 steps of 0.014 s
AFTER_THE_RUN = 1.0  # [s] robots: the recording goes on this long after the run
SPEED, FPS, WIDTH, HEIGHT = 2.0, 20, 640, 480
# Standard deviation of the pixel values (0..255) of a frame: measured 12.5 for rviz's empty grid
# at this size, 21 to 23 with the hexagon drawn.
BLANK_STD = 17.0
TOOLS = ("Xvfb", "rviz", "rosbag", "rosmaster", "ffprobe")  # render_bag.py's tools but ffmpeg


def render_bag():
    return roslib.packages.find_node(PKG, "render_bag.py")[0]


def test_display(offset=0):
    display = os.environ.get("VF_TEST_DISPLAY")
    return f":{int(display.lstrip(':')) + offset}" if display else None


def proc_stat(pid):
    """(parent pid, process group, start time) of a live process, or None (also for a zombie,
    which no longer runs and waits for init to reap it)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        if fields[0] in ("Z", "X"):
            return None
        return int(fields[1]), int(fields[2]), int(fields[19])
    except (OSError, IndexError, ValueError):
        return None


# The robots' bodies in the MuJoCo render: the agents' colours that no other marker of that
# render has (the tf axes are red, green and blue, converged edges green): orange, purple, cyan.
UNSHARED_COLOURS = (3, 4, 5)
BODY_PIXELS = 8  # a body 0.21 m across covers about 40 pixels of the 640x480 fit view; measured 17 to 85


def solid_pixels(image):
    """Per colour of PALETTE, the pixels of an RGB image in [0, 1] that show it solid: its hue
    (within 0.02, the nearest of PALETTE's), saturation above 0.7, and at least half its
    brightness (HSV value). A halo (opacity 0.35) over rviz's dark background has neither: it
    blends with the grey."""
    import colorsys

    import matplotlib.colors
    hsv = matplotlib.colors.rgb_to_hsv(image[:, :, :3])
    own = [colorsys.rgb_to_hsv(*rgb) for rgb in vf_rostest.PALETTE]
    distance = np.stack([np.minimum(abs(hsv[:, :, 0] - h), 1 - abs(hsv[:, :, 0] - h)) for h, _, _ in own])
    nearest, close = distance.argmin(axis=0), distance.min(axis=0) < 0.02
    return [int((close & (nearest == k) & (hsv[:, :, 1] > 0.7) & (hsv[:, :, 2] > 0.5 * v)).sum())
            for k, (_, _, v) in enumerate(own)]


class Watched:
    """A render_bag.py process and every process it starts, seen by polling /proc every 0.1 s
    (the render's processes live for seconds)."""

    def __init__(self, args, env=None):
        self.proc = subprocess.Popen(["/usr/bin/python3", render_bag()] + args, env=env, stdin=subprocess.DEVNULL,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.seen = {}  # pid: (process group, start time, command line)
        self.done = threading.Event()
        self.thread = threading.Thread(target=self.watch, daemon=True)
        self.thread.start()

    def watch(self):
        while not self.done.is_set():
            family = {self.proc.pid}
            stats = {}
            for entry in os.listdir("/proc"):
                if entry.isdigit():
                    stat = proc_stat(int(entry))
                    if stat:
                        stats[int(entry)] = stat
            grew = True
            while grew:
                grew = False
                for pid, (parent, _, _) in stats.items():
                    if parent in family and pid not in family:
                        family.add(pid)
                        grew = True
            for pid in family - {self.proc.pid}:
                # Read again at every poll: a child seen between its fork and its exec still
                # shows the render's own command line (a CI run once missed ffmpeg that way).
                try:
                    with open(f"/proc/{pid}/cmdline") as f:
                        cmdline = f.read().replace("\0", " ").strip()
                except OSError:
                    cmdline = ""
                known = self.seen.get(pid)
                if known is None or (known[1] == stats[pid][2] and cmdline):
                    self.seen[pid] = (stats[pid][1], stats[pid][2], cmdline or "?")
            time.sleep(0.1)

    def running(self, word):
        return any(word in cmd for _, _, cmd in self.seen.values())

    def finish(self, timeout=300):
        out, err = self.proc.communicate(timeout=timeout)
        self.done.set()
        self.thread.join()
        return self.proc.returncode, out, err

    def left_behind(self):
        """Processes the render started that still run: by pid (same start time) or process group."""
        groups = {group for group, _, _ in self.seen.values()} - {os.getpgrp()}
        left = [cmd for pid, (_, start, cmd) in self.seen.items() if (proc_stat(pid) or (0, 0, -1))[2] == start]
        for entry in os.listdir("/proc"):
            stat = proc_stat(int(entry)) if entry.isdigit() else None
            if stat and stat[1] in groups and int(entry) not in self.seen:
                left.append(f"pid {entry} in group {stat[1]}")
        return left


class RecordedHexagon(unittest.TestCase):
    """The hexagon's run that the launch records (its result, its bag), and a folder for videos."""

    @classmethod
    def wait_for_the_run(cls):
        rospy.init_node("render_test")
        cls.out = rospy.get_param("~output_dir")
        cls.result = vf_rostest.wait_for_result(os.path.join(cls.out, "hexagon.result.yaml"), 120.0)
        cls.bag = os.path.join(cls.out, "hexagon.bag")
        cls.tmp = tempfile.mkdtemp(prefix="render_test_")

    @classmethod
    def remove_files(cls):
        shutil.rmtree(cls.out, ignore_errors=True)
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def setUp(self):
        self.assertEqual(self.result.get("result"), "succeeded", f"the recorded run: {self.result}")


@vf_rostest.reported_setup
class RenderTest(RecordedHexagon):
    @classmethod
    def setUpClass(cls):
        cls.wait_for_the_run()

    @classmethod
    def tearDownClass(cls):
        cls.remove_files()

    def render(self, *args, env=None):
        display = test_display()
        return Watched(list(args) + (["--display", display] if display else []), env=env)

    def assert_nothing_left(self, watched):
        self.assertTrue(watched.seen, "the render started no process")
        self.assertEqual(watched.left_behind(), [], "processes of the render still running")

    def assert_one_line_error(self, result, status, words):
        code, out, err = result
        self.assertEqual(code, status, f"exit status; stderr: {err}")
        self.assertEqual(out, "")
        self.assertEqual(len(err.strip().splitlines()), 1, f"one line on stderr, got: {err}")
        for word in words:
            self.assertIn(word, err)

    def test_videos_of_the_run(self):
        self.assertTrue(os.path.exists(self.bag[:-len(".bag")] + "_1.bag"), "the recording is not split")
        outs = [os.path.join(self.tmp, "hexagon.mp4"), os.path.join(self.tmp, "hexagon.gif")]
        watched = self.render(self.bag, "--out", *outs, "--speed", str(SPEED), "--fps", str(FPS),
                              "--size", f"{WIDTH}x{HEIGHT}")
        code, out, err = watched.finish()
        self.assertEqual(code, 0, err)
        self.assertEqual(len(out.splitlines()), 1, f"one line on stdout (not a terminal: no progress): {out}")
        self.assertTrue(out.startswith("render_bag: wrote"), out)
        self.assert_nothing_left(watched)
        for path, codec in zip(outs, ("h264", "gif")):
            with self.subTest(video=os.path.basename(path)):
                self.check_video(path, codec)

    def check_video(self, path, codec):
        probe = subprocess.run(["ffprobe", "-v", "error", "-select_streams", "v:0", "-show_entries",
                                "stream=codec_name,width,height:format=duration", "-of", "default=noprint_wrappers=1",
                                path], capture_output=True, text=True, check=True).stdout
        info = dict(line.split("=", 1) for line in probe.split())
        self.assertEqual((info["codec_name"], int(info["width"]), int(info["height"])), (codec, WIDTH, HEIGHT))
        self.assertAlmostEqual(float(info["duration"]), RUN_SECONDS / SPEED, delta=0.1 * RUN_SECONDS / SPEED)
        raw = subprocess.run(["ffmpeg", "-v", "error", "-i", path, "-f", "rawvideo", "-pix_fmt", "rgb24", "-"],
                             capture_output=True, check=True).stdout
        frames = np.frombuffer(raw, dtype=np.uint8).reshape(-1, HEIGHT, WIDTH, 3)
        self.assertGreater(len(frames), 0.9 * FPS * RUN_SECONDS / SPEED)
        spread = [float(f.std()) for f in frames]
        blank = [k for k, s in enumerate(spread) if s <= BLANK_STD]
        self.assertEqual(blank, [], f"blank frames (pixel std <= {BLANK_STD}; lowest {min(spread):.1f})")
        for rgb, count in zip(vf_rostest.PALETTE, vf_rostest.agent_colour_pixels(frames[-1] / 255.0)):
            self.assertGreater(count, 30, f"an agent's colour {rgb} is not in the last frame")
        # The formation settles and its edges turn from red to green: measured 5% of the pixels.
        changed = np.abs(frames[0].astype(int) - frames[-1].astype(int)).max(axis=2) > 30
        self.assertGreater(changed.mean(), 0.01, "the first and last frames are nearly the same")

    def test_namespaced_team(self):
        # The hexagon's bag as a team under <group ns="team_a"> records it: topics /team_a/formation/...
        # and frames team_a/formation/agent_<i> (rewritten here rather than run again).
        import rosbag
        bag = os.path.join(self.tmp, "team_a_hexagon.bag")
        with rosbag.Bag(bag, "w") as out:
            for part in [self.bag] + [f"{self.bag[:-len('.bag')]}_{k}.bag" for k in range(1, 100)]:
                if not os.path.exists(part):
                    break
                with rosbag.Bag(part) as recorded:
                    for topic, msg, t in recorded.read_messages():
                        if topic == "/tf":
                            for transform in msg.transforms:
                                transform.child_frame_id = "team_a/" + transform.child_frame_id
                        out.write(topic if topic == "/tf" else "/team_a" + topic, msg, t)
        self.assert_one_line_error(self.render(bag, "--ns", "team_b").finish(), 2, ["--ns team_b", "/team_a"])
        video = os.path.join(self.tmp, "team_a.mp4")
        code, _, err = self.render(bag, "--ns", "team_a", "--out", video, "--speed", "4", "--fps", "10",
                                   "--size", "320x240").finish()
        self.assertEqual(code, 0, err)
        raw = subprocess.run(["ffmpeg", "-v", "error", "-sseof", "-0.3", "-i", video, "-f", "rawvideo", "-pix_fmt",
                              "rgb24", "-"], capture_output=True, check=True).stdout
        last = np.frombuffer(raw, dtype=np.uint8).reshape(-1, 240, 320, 3)[-1]
        for rgb, count in zip(vf_rostest.PALETTE, vf_rostest.agent_colour_pixels(last / 255.0)):
            self.assertGreater(count, 5, f"an agent's colour {rgb} is not in the team's last frame")

    def test_ctrl_c_stops_everything(self):
        watched = self.render(self.bag, "--out", os.path.join(self.tmp, "stopped.mp4"), "--speed", "0.25",
                              "--fps", "10", "--size", "320x240")
        end = time.time() + 120
        while not watched.running("x11grab") and time.time() < end and watched.proc.poll() is None:
            time.sleep(0.1)
        if not watched.running("x11grab"):
            status = watched.proc.poll()
            if status is None:
                watched.proc.kill()
            _, out, err = watched.finish()
            self.fail(f"the capture never started (render exit status {status}): {(out + err)[-1500:]}")
        time.sleep(3.0)  # into the replay, which lasts 4.2 s / 0.25 = 17 s
        watched.proc.send_signal(signal.SIGINT)
        self.assert_one_line_error(watched.finish(), 130, ["interrupted"])
        self.assert_nothing_left(watched)
        self.assertFalse(os.path.exists(os.path.join(self.tmp, "stopped.mp4")))

    def test_no_bag(self):
        missing = os.path.join(self.tmp, "no_such.bag")
        self.assert_one_line_error(self.render(missing).finish(), 2, [missing, "no such bag"])

    def test_empty_bag(self):
        import rosbag
        empty = os.path.join(self.tmp, "empty.bag")
        rosbag.Bag(empty, "w").close()
        self.assert_one_line_error(self.render(empty).finish(), 2, [empty, "empty"])

    def test_no_ffmpeg(self):
        tools = os.path.join(self.tmp, "tools")
        os.makedirs(tools, exist_ok=True)
        for tool in TOOLS:
            target = os.path.join(tools, tool)
            if not os.path.exists(target):
                os.symlink(shutil.which(tool), target)
        env = dict(os.environ, PATH=tools)
        self.assert_one_line_error(self.render(self.bag, env=env).finish(), 2, ["ffmpeg is not installed"])

    def test_display_that_cannot_start(self):
        read_end, write_end = os.pipe()
        wanted = test_display(1)
        taken = subprocess.Popen(["Xvfb"] + ([wanted] if wanted else []) + ["-nolisten", "tcp", "-displayfd",
                                                                           str(write_end)],
                                 pass_fds=(write_end,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.close(write_end)
        try:
            ready, _, _ = select.select([read_end], [], [], 30)
            self.assertTrue(ready, "the test's own Xvfb did not start")
            display = ":" + os.read(read_end, 64).decode().strip()
            watched = Watched([self.bag, "--out", os.path.join(self.tmp, "x.mp4"), "--display", display])
            self.assert_one_line_error(watched.finish(), 1, [f"the display {display} cannot start"])
            self.assert_nothing_left(watched)
        finally:
            os.close(read_end)
            taken.terminate()
            taken.wait()

    def test_rviz_that_dies(self):
        # Qt cannot load a platform plugin that does not exist: rviz exits at start.
        env = dict(os.environ, QT_QPA_PLATFORM="no_such_platform")
        watched = self.render(self.bag, "--out", os.path.join(self.tmp, "x.mp4"), env=env)
        self.assert_one_line_error(watched.finish(), 1, ["rviz died"])
        self.assert_nothing_left(watched)


@vf_rostest.reported_setup
class RenderRobotsTest(RecordedHexagon):
    @classmethod
    def setUpClass(cls):
        cls.wait_for_the_run()
        # The recording goes on after the run until the launch ends; then a clean stop closes the bag.
        time.sleep(AFTER_THE_RUN)
        subprocess.run(["rosnode", "kill", "/formation/recorder"], capture_output=True)
        end = time.time() + 15
        while not os.path.exists(cls.bag) and time.time() < end:
            time.sleep(0.2)

    @classmethod
    def tearDownClass(cls):
        cls.remove_files()

    def test_the_video_is_the_run(self):
        import rosbag
        with rosbag.Bag(self.bag) as bag:
            length = bag.get_end_time() - bag.get_start_time()
            # rosbag record may join some steps into the run (the timed monitor does not wait for it).
            joined = next(bag.read_messages(topics=["/formation/status"]))[1].time
        # What makes the check below tell the run from the bag.
        self.assertGreater(length, RUN_SECONDS - joined + AFTER_THE_RUN, "the bag holds no time around the run")
        video = os.path.join(self.tmp, "robots.mp4")
        display = test_display()
        watched = Watched([self.bag, "--out", video, "--speed", str(SPEED), "--fps", str(FPS), "--size",
                           f"{WIDTH}x{HEIGHT}"] + (["--display", display] if display else []))
        code, out, err = watched.finish()
        self.assertEqual(code, 0, err)
        # The run from its first recorded step (or the next, whose markers the bag holds) to its end.
        shown = re.search(r"([0-9.]+)\.\.([0-9.]+) s of the run", out)
        self.assertTrue(shown, out)
        self.assertAlmostEqual(float(shown[1]), joined, delta=2 * STEP + 0.005, msg=out)
        self.assertEqual(shown[2], f"{RUN_SECONDS:.2f}", out)
        # The first shown step's t, printed to 10 ms (the steps are 14 ms apart), and the video
        # from its picture to the last step's.
        seconds = (RUN_SECONDS - round(float(shown[1]) / STEP) * STEP) / SPEED
        probe = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
                                "stream=r_frame_rate,start_time,nb_read_frames:format=duration", "-of",
                                "default=noprint_wrappers=1", video], capture_output=True, text=True, check=True)
        info = dict(line.split("=", 1) for line in probe.stdout.split())
        count, why = int(info["nb_read_frames"]), f"the video's frames for {seconds:.3f} s; {out}; {info}"
        # At the frame rate from 0 s, no slot without a picture: its length is its frames'.
        self.assertEqual(info["r_frame_rate"], f"{FPS}/1", why)
        self.assertAlmostEqual(float(info["start_time"]), 0.0, delta=1e-3, msg=why)
        self.assertAlmostEqual(float(info["duration"]), count / FPS, delta=1e-3, msg=why)
        # Frames 1/FPS apart: the last at or after the run's last step (it shows it), the one
        # before it before (no frame past the run's end).
        self.assertGreaterEqual((count - 1) / FPS, seconds - 1e-4, why)
        self.assertLess((count - 2) / FPS, seconds, f"{why}; the bag lasts {length:.2f} s")
        raw = subprocess.run(["ffmpeg", "-v", "error", "-i", video, "-f", "rawvideo", "-pix_fmt", "rgb24", "-"],
                             capture_output=True, check=True).stdout
        frames = np.frombuffer(raw, dtype=np.uint8).reshape(-1, HEIGHT, WIDTH, 3)
        # The markers of the run throughout: rviz may draw the first picture's markers a frame late.
        counts = [vf_rostest.agent_colour_pixels(frame / 255.0) for frame in frames]
        without = [k for k, c in enumerate(counts) if min(c) <= 30]
        self.assertLessEqual(len(without), 0.1 * len(frames),
                             f"frames without every agent's colour: {[(k, counts[k]) for k in without]}")
        self.assertNotIn(len(frames) - 1, without, "the last frame lacks an agent")
        self.check_last_frame(frames[-1] / 255.0)

    def check_last_frame(self, image):
        """More checks of the video's last picture (RGB in [0, 1]), by the kind of bag."""


class RenderMujocoTest(RenderRobotsTest):
    """RenderRobotsTest on robots.launch world:=mujoco (unicycles), plus the world's markers (its
    setUpClass, reported as there)."""

    def check_last_frame(self, image):
        # Each robot's body, solid in its agent's colour inside that agent's translucent halo, is
        # in the picture (the colours of other markers too left aside).
        solid = solid_pixels(image)
        for k in UNSHARED_COLOURS:
            self.assertGreaterEqual(solid[k], BODY_PIXELS,
                                    f"robot {k}'s body ({vf_rostest.PALETTE[k]}) is not in the last frame: {solid}")

    def test_the_bag_holds_the_worlds_markers(self):
        import rosbag
        odom = {}  # (robot, stamp [ns]) -> (x, y, heading) of the odometry (ground truth)
        arrays = []
        with rosbag.Bag(self.bag) as bag:
            for topic, msg, _ in bag.read_messages(topics=[f"/formation/robot_{i}/odom" for i in range(6)] +
                                                   ["/formation/world/markers"]):
                if topic.endswith("/odom"):
                    q = msg.pose.pose.orientation
                    odom[(int(topic.split("_")[1].split("/")[0]), msg.header.stamp.to_nsec())] = (
                        msg.pose.pose.position.x, msg.pose.pose.position.y,
                        np.arctan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z)))
                else:
                    arrays.append(msg)
        # ~marker_rate 20 Hz from when rosbag record joined the topic (it joins topics one by one,
        # on a loaded machine seconds apart) to the end of the recording, after the run's end.
        stamps = sorted(a.markers[0].header.stamp.to_sec() for a in arrays)
        self.assertGreater(stamps[-1] - stamps[0], AFTER_THE_RUN, "world markers recorded")
        self.assertGreater(len(stamps), 0.9 * 20 * (stamps[-1] - stamps[0]), "world markers at 20 Hz")
        self.assertLess(max(b - a for a, b in zip(stamps, stamps[1:])), 0.5, "a gap in the world's markers")
        compared = 0
        for array in arrays:
            spaces = {}
            for m in array.markers:
                spaces.setdefault(m.ns, []).append(m)
            self.assertEqual(sorted(m.id for m in spaces["bodies"]), list(range(6)))
            self.assertEqual(sorted(m.id for m in spaces["headings"]), list(range(6)))
            self.assertEqual({m.color.a for m in spaces["bodies"]}, {1.0}, "the bodies are drawn solid")
            for body, arrow in zip(sorted(spaces["bodies"], key=lambda m: m.id),
                                   sorted(spaces["headings"], key=lambda m: m.id)):
                self.assertGreater(arrow.points[0].z, body.pose.position.z + body.scale.z / 2, "arrow on the body")
                # Out of the agent's sphere (radius 0.3 m on the side-3 hexagon): twice its radius.
                self.assertAlmostEqual(np.hypot(arrow.points[1].x - arrow.points[0].x,
                                                arrow.points[1].y - arrow.points[0].y), 0.6, places=9)
            # The hexagon's robots never touch: the contact markers stay deleted.
            self.assertEqual({m.action for m in spaces["touching"] + spaces["contacts"]}, {m.DELETE})
            for arrow in spaces["headings"]:
                pose = odom.get((arrow.id, arrow.header.stamp.to_nsec()))
                if pose is None:  # the odometry of the same instant was not recorded
                    continue
                compared += 1
                start, end = arrow.points
                self.assertAlmostEqual(start.x, pose[0], places=9)
                self.assertAlmostEqual(start.y, pose[1], places=9)
                heading = np.arctan2(end.y - start.y, end.x - start.x)
                self.assertAlmostEqual(float(np.angle(np.exp(1j * (heading - pose[2])))), 0.0, places=9)
        self.assertGreater(compared, 0.9 * 6 * len(arrays), "heading arrows compared with the odometry")
        # The monitor of a robot run draws its agents as halos round the bodies (opacity 0.35).
        with rosbag.Bag(self.bag) as bag:
            halos = {round(c.a, 6) for _, msg, _ in bag.read_messages(topics=["/formation/markers"])
                     for m in msg.markers if m.ns == "agents" for c in m.colors}
        self.assertEqual(halos, {0.35}, "the agents' opacity in a robot run")


if __name__ == "__main__":
    kind = {"robots": RenderRobotsTest, "mujoco": RenderMujocoTest}
    chosen = next((kind[a] for a in sys.argv[1:] if a in kind), RenderTest)
    rostest.rosrun(PKG, "render_test", chosen, sys.argv)
