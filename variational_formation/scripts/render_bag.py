#!/usr/bin/python3
"""Renders a recorded run the way rviz shows it (config/formation.rviz: the markers, the tf
frames, the status text) to an MP4, a GIF or both, with no desktop.

It starts a ROS master of its own on a free port (with /use_sim_time), Xvfb, and rviz full
screen on it; replays the bag with `rosbag play --clock` at --speed, and captures the display
with ffmpeg (x11grab). The video lasts (to - from) / speed seconds and one to two frames
(video_frames). A bag split by the recorder (<name>.bag, <name>_1.bag, ...) is read whole from
its first part. Every process it starts is stopped when it ends, also on Ctrl-C or SIGTERM.

usage: render_bag.py BAG [BAG ...] [--out FILE.mp4 [FILE.gif]] [--speed S] [--size WxH]
                     [--fps N] [--from SEC] [--to SEC] [--ns NAMESPACE] [--camera fit|config]
                     [--display :N] [--port P]
Details: doc/render.md.
"""
import argparse
import math
import os
import re
import select
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

import yaml

# The package is importable once devel/setup.bash is sourced; this also finds it in a checkout.
sys.path.append(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src"))
from variational_formation.cli import fail  # noqa: E402
from variational_formation.run_clock import RunSpan  # noqa: E402

FORMATS = (".mp4", ".gif")
TOOLS = {"ffmpeg": "ffmpeg", "ffprobe": "ffmpeg", "Xvfb": "xvfb", "rviz": "rviz", "rosbag": "python3-rosbag",
         "rosmaster": "python3-rosmaster"}  # each with its Debian package
MARKERS = "/formation/markers"  # the topic config/formation.rviz shows, below a team's namespace
WORLD_MARKERS = "/formation/world/markers"  # a MuJoCo world's bodies, headings and contacts (display World)
TF_SCALE = 8.0  # tf axes and names: this many sphere radii
AGENT_FRAME = re.compile(r"(^|/)formation/agent_\d+$")  # an agent's tf frame, below any team namespace
FIT_DISTANCE = 3.0  # camera distance over the formation's reach (half the box's diagonal)
WARM_UP = 1.0  # seconds rviz gets to draw the first instant before the replay goes on
LATENCY_MAX = 1.0  # seconds rviz may take to draw what it receives
STARTUP_TIMEOUT = 60.0  # seconds for the master, the display, rviz and the capture to come up


class RenderError(Exception):
    """Something the render needs failed at run time (exit status 1)."""


class Interrupted(Exception):
    """Ctrl-C, SIGTERM or SIGHUP."""


def parse_args():
    parser = argparse.ArgumentParser(description=" ".join(__doc__.split("\n\n")[0].split()))
    parser.add_argument("bags", nargs="+", metavar="BAG",
                        help="a bag of formation.launch record:=true or robots.launch record:=true; the other "
                             "parts of a split bag are found next to its first one")
    parser.add_argument("--out", nargs="+", default=None,
                        help="output files, .mp4 and/or .gif (default: the bag's name with .mp4)")
    parser.add_argument("--speed", type=float, default=1.0, help="replay speed, > 0 (default 1: the run's pace)")
    parser.add_argument("--size", default="1100x800", help="video size WxH in pixels (default 1100x800)")
    parser.add_argument("--fps", type=int, default=25, help="frames per second, 1..60 (default 25)")
    parser.add_argument("--from", dest="start", type=float, default=0.0,
                        help="seconds of the run's own time (t = k h of the status, from its first step) to start at")
    parser.add_argument("--to", dest="end", type=float, default=None,
                        help="seconds of the run's own time to end at (default: its last step in the bag)")
    parser.add_argument("--ns", default=None,
                        help="the team's namespace (topics /NS/formation/...); default: the bag's only team")
    parser.add_argument("--camera", choices=("fit", "config"), default="fit",
                        help="fit: the camera looks at the centre of the formation from a distance that shows all "
                             "of it (default); config: the view of config/formation.rviz")
    parser.add_argument("--display", default=None,
                        help="X display number for Xvfb, like :42 (default: a free one)")
    parser.add_argument("--port", type=int, default=0, help="port of the private ROS master (default: a free one)")
    args = parser.parse_args()
    if not args.speed > 0 or args.speed > 1000:
        fail(f"--speed: must be in (0, 1000], got {args.speed}")
    match = re.fullmatch(r"(\d+)x(\d+)", args.size)
    if not match or not (64 <= int(match[1]) <= 7680 and 64 <= int(match[2]) <= 4320):
        fail(f"--size: expected WxH with W in 64..7680 and H in 64..4320, got '{args.size}'")
    # yuv420p (what players expect of an MP4) needs even sides.
    args.width, args.height = int(match[1]) // 2 * 2, int(match[2]) // 2 * 2
    if not 1 <= args.fps <= 60:
        fail(f"--fps: must be in 1..60, got {args.fps}")
    if not args.start >= 0:
        fail(f"--from: must be >= 0 seconds, got {args.start}")
    if args.end is not None and not args.end > args.start:
        fail(f"--to: must be after --from ({args.start} s), got {args.end}")
    if args.display is not None and not re.fullmatch(r":\d+", args.display):
        fail(f"--display: expected :N, got '{args.display}'")
    if not 0 <= args.port <= 65535:
        fail(f"--port: must be in 0..65535, got {args.port}")
    args.bags = bag_parts(args.bags)
    if args.out is None:
        args.out = [re.sub(r"\.bag$", "", args.bags[0]) + ".mp4"]
    for out in args.out:
        if os.path.splitext(out)[1].lower() not in FORMATS:
            fail(f"--out: '{out}' is neither .mp4 nor .gif")
        directory = os.path.dirname(os.path.abspath(out))
        if not os.path.isdir(directory):
            fail(f"--out: the directory of '{out}' does not exist")
    for tool, package in TOOLS.items():
        if shutil.which(tool) is None:
            fail(f"{tool} is not installed or not on PATH (Debian: apt-get install {package})")
    return args


def bag_parts(paths):
    """The files to replay: each given bag, and after <name>.bag the recorder's <name>_1.bag, ...
    (a part given explicitly is not added twice)."""
    parts = []
    for path in paths:
        if not os.path.isfile(path):
            fail(f"{path}: no such bag")
        if path in parts:
            continue
        parts.append(path)
        stem = re.sub(r"\.bag$", "", path)
        k = 1
        while os.path.isfile(f"{stem}_{k}.bag"):
            if f"{stem}_{k}.bag" not in parts:
                parts.append(f"{stem}_{k}.bag")
            k += 1
    return parts


class BagContents:
    """The bag's parts, their time span, topics and the topics' types."""

    def __init__(self, parts):
        import rosbag
        self.parts = parts
        self.topics, self.count, self.start, self.end = {}, 0, None, None
        for path in parts:
            try:
                with rosbag.Bag(path) as bag:
                    info = bag.get_type_and_topic_info()
                    for topic, t in info.topics.items():
                        self.topics[topic] = t.msg_type
                    count = bag.get_message_count()
                    self.count += count
                    if count:
                        self.start = min(bag.get_start_time(), self.start or float("inf"))
                        self.end = max(bag.get_end_time(), self.end or 0.0)
            except Exception as e:  # rosbag raises several unrelated types for unreadable files
                fail(f"{path}: cannot read the bag ({' '.join(str(e).split()) or type(e).__name__})")
        if self.count == 0:
            fail(f"{parts[0]}: the bag is empty (no messages{' in any of its %d parts' % len(parts) if len(parts) > 1 else ''})")

    def teams(self):
        """The namespaces ('' for none) below which the bag holds a formation's topics."""
        return sorted({m[1] for t in self.topics
                       for m in [re.fullmatch(r"(.*)/formation/(markers|status)", t)] if m})


def choose_topics(contents, ns):
    """(namespace prefix, markers topic or None, odometry topics, every topic to replay). A MuJoCo
    world's markers, where the bag has them, are replayed too (world_markers)."""
    teams = contents.teams()
    if ns is not None:
        prefix = "/" + ns.strip("/") if ns.strip("/") else ""
        if prefix not in teams:
            fail(f"--ns {ns}: the bag holds no {prefix}/formation/... topics (teams in it: "
                 f"{', '.join(t or '/ (no namespace)' for t in teams) or 'none'})")
    elif len(teams) > 1:
        fail(f"the bag holds several teams ({', '.join(t or '/' for t in teams)}): choose one with --ns")
    else:
        prefix = teams[0] if teams else ""
    markers = prefix + MARKERS if prefix + MARKERS in contents.topics else None
    # The robots' odometry (robots.launch), shown only where the bag has no markers to show.
    odometry = [] if markers else sorted(t for t, kind in contents.topics.items()
                                         if kind == "nav_msgs/Odometry" and t.startswith(prefix + "/formation/"))
    replay = [t for t in (markers, world_markers(contents, prefix), "/tf", "/tf_static") if t in contents.topics]
    replay += odometry
    if not markers and "/tf" not in contents.topics and not odometry:
        fail(f"nothing in the bag that rviz shows: no {prefix}{MARKERS}, /tf or robot odometry "
             f"(topics: {', '.join(sorted(contents.topics))})")
    return prefix, markers, odometry, replay


def world_markers(contents, prefix):
    """The MuJoCo world's markers topic of the team (robots.launch world:=mujoco), or None."""
    topic = prefix + WORLD_MARKERS
    return topic if topic in contents.topics else None


def first_instant(contents, topics, first):
    """How many of the replayed messages share the earliest bag time from `first` on, and the bag
    time that follows it (None if there is none)."""
    import rosbag
    import rospy
    times = []
    for path in contents.parts:
        with rosbag.Bag(path) as bag:
            for k, (_, _, t) in enumerate(bag.read_messages(topics=topics, start_time=rospy.Time.from_sec(first))):
                times.append(t.to_sec())
                if k > 1000 or t.to_sec() > times[0]:
                    break
    times.sort()
    later = [t for t in times if t > times[0]] if times else []
    return times.count(times[0]) if times else 0, later[0] if later else None


class Scene:
    """Where the replayed span happens, for the camera: the parent frame of the recorded transforms
    (rviz's fixed frame), the box around every transform's origin in it, and the radius of the
    agents' spheres (the monitor's markers scale with the formation: doc/render.md, step 1)."""

    def __init__(self, contents, markers, first, last):
        import rosbag
        import rospy
        self.fixed_frame, self.radius = None, None
        self.frames = set()  # every child frame of the recorded transforms
        self.low, self.high = [float("inf")] * 3, [float("-inf")] * 3
        window = {"start_time": rospy.Time.from_sec(first), "end_time": rospy.Time.from_sec(last)}
        for path in contents.parts:
            with rosbag.Bag(path) as bag:
                for _, msg, _ in bag.read_messages(topics=["/tf"], **window):
                    for t in msg.transforms:
                        self.frames.add(t.child_frame_id.lstrip("/"))
                        self.fixed_frame = self.fixed_frame or t.header.frame_id.lstrip("/")
                        if t.header.frame_id.lstrip("/") == self.fixed_frame:
                            p = t.transform.translation
                            self.low = [min(a, b) for a, b in zip(self.low, (p.x, p.y, p.z))]
                            self.high = [max(a, b) for a, b in zip(self.high, (p.x, p.y, p.z))]
                if markers and self.radius is None:
                    for _, msg, _ in bag.read_messages(topics=[markers], **window):
                        spheres = [m.scale.x / 2 for m in msg.markers if m.ns == "agents"]
                        if spheres:
                            self.radius = spheres[0]
                            break

    def bounded(self):
        return self.low[0] <= self.high[0]


def rviz_config(template, markers, odometry, scene, args, world=None):
    """config/formation.rviz for this bag: the team's markers topic, the world's (`world`; its
    display is dropped where the bag has none), the bag's fixed frame, the window at the video's
    size, the camera on the formation (--camera fit), tf frames drawn at the formation's scale, and
    the robots' odometry where the bag has no markers."""
    with open(template) as f:
        config = yaml.safe_load(f)
    manager = config["Visualization Manager"]
    agents = {f for f in scene.frames if AGENT_FRAME.search(f)}
    others = scene.frames - agents - {scene.fixed_frame}
    for display in list(manager["Displays"]):
        if display.get("Class") == "rviz/MarkerArray" and display.get("Name") == "World":
            if world:
                display["Marker Topic"] = world
            else:
                manager["Displays"].remove(display)
        elif display.get("Class") == "rviz/MarkerArray" and markers:
            display["Marker Topic"] = markers
        if display.get("Class") == "rviz/TF" and scene.radius:
            # Axes and names that stick out of the agents' spheres: the spheres' radius is a tenth
            # of the shortest desired distance.
            display["Marker Scale"] = round(TF_SCALE * scene.radius, 3)
        if display.get("Class") == "rviz/TF" and agents and others:
            # A robot's base_link sits on (or a hand offset from) its agent's frame, and the two
            # names would be drawn on top of each other: one name per robot, the agent's; the
            # robots' frames keep their axes, in a second display without names.
            display["Frames"] = {"All Enabled": True, **{f: {"Value": False} for f in sorted(others)}}
            manager["Displays"].append(dict(display, Name="Robot frames", **{"Show Names": False}, Frames={
                "All Enabled": True, **{f: {"Value": False} for f in sorted(agents | {scene.fixed_frame})}}))
    for k, topic in enumerate(odometry):
        manager["Displays"].append({
            "Class": "rviz/Odometry", "Enabled": True, "Name": topic, "Topic": topic, "Keep": 1,
            "Position Tolerance": 0.0, "Angle Tolerance": 0.0, "Covariance": {"Value": False}, "Value": True,
            "Shape": {"Value": "Arrow", "Color": palette(k), "Alpha": 1, "Shaft Length": 0.6, "Shaft Radius": 0.08,
                      "Head Length": 0.25, "Head Radius": 0.18}})
    if scene.fixed_frame:
        manager["Global Options"]["Fixed Frame"] = scene.fixed_frame
    manager["Global Options"]["Frame Rate"] = args.fps
    view = manager["Views"]["Current"]
    if args.camera == "fit" and scene.bounded():
        centre = [(a + b) / 2 for a, b in zip(scene.low, scene.high)]
        reach = 0.5 * sum((b - a) ** 2 for a, b in zip(scene.low, scene.high)) ** 0.5 + 2 * (scene.radius or 0.0)
        # About the config's view of the hexagon (14 m for a reach of 4.6 m at 1100 x 800),
        # farther for pictures taller than that.
        aspect = max(1.0, (args.height / args.width) / (800 / 1100))
        view["Focal Point"] = {"X": centre[0], "Y": centre[1], "Z": centre[2]}
        view["Distance"] = round(max(1.0, FIT_DISTANCE * reach * aspect), 3)
    config["Window Geometry"].update({"Width": args.width, "Height": args.height, "X": 0, "Y": 0,
                                      "Hide Left Dock": True, "Hide Right Dock": True})
    return yaml.safe_dump(config, sort_keys=False)


def palette(k):
    colours = ["230; 25; 75", "60; 180; 75", "255; 225; 25", "0; 130; 200", "245; 130; 48", "145; 30; 180"]
    return colours[k % len(colours)]


def group_runs(group):
    """Whether a process of process group `group`, other than a zombie, is alive."""
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if len(fields) > 2 and int(fields[2]) == group and fields[0] not in ("Z", "X"):
            return True
    return False


class Processes:
    """The processes of one render, each the leader of its own process group, so that stopping it
    stops its children too (rosbag play's player, ...)."""

    def __init__(self, log_dir):
        self.log_dir = log_dir
        self.running = []  # (name, Popen), in start order

    def start(self, name, cmd, env=None, **kwargs):
        log = open(os.path.join(self.log_dir, name + ".log"), "wb")
        kwargs.setdefault("stdout", log)
        kwargs.setdefault("stderr", log)
        try:
            p = subprocess.Popen(cmd, env=env, stdin=kwargs.pop("stdin", subprocess.DEVNULL), start_new_session=True,
                                 **kwargs)
        except OSError as e:
            raise RenderError(f"cannot start {cmd[0]}: {e.strerror}")
        finally:
            log.close()
        self.running.append((name, p))
        return p

    def log_tail(self, name):
        """The last line of a process's output that says something, or ''."""
        try:
            with open(os.path.join(self.log_dir, name + ".log"), errors="replace") as f:
                lines = [l.strip() for l in f.read().replace("\r", "\n").splitlines() if l.strip()]
        except OSError:
            return ""
        # Without X's "(EE)" marks, colours, and the librospack line rviz prints at every start.
        lines = [re.sub(r"\(EE\)|\x1b\[[0-9;]*m", "", l).strip() for l in lines if "librospack" not in l]
        fatal = [l for l in lines if re.search(r"fatal|error|cannot|could not|failed", l, re.I)]
        return (fatal or [l for l in lines if l] or [""])[-1][:200]

    def stop(self, p, first_signal=signal.SIGTERM, timeout=5.0):
        """Stops p's process group: first_signal, then SIGKILL after `timeout` seconds."""
        for sig, wait in ((first_signal, timeout), (signal.SIGKILL, 5.0)):
            try:
                os.killpg(p.pid, sig)
            except ProcessLookupError:
                pass
            try:
                p.wait(timeout=wait)
                break
            except subprocess.TimeoutExpired:
                continue
        # The leader may be gone while others of its group are not. SIGKILL is delivered
        # asynchronously: wait until no process of the group runs any more, so that none
        # outlives the render (a zombie left to init to reap does not run).
        deadline = time.monotonic() + 5.0
        while True:
            try:
                os.killpg(p.pid, signal.SIGKILL)
            except ProcessLookupError:
                break
            if not group_runs(p.pid) or time.monotonic() > deadline:
                break
            time.sleep(0.02)

    def stop_all(self):
        while self.running:
            _, p = self.running.pop()
            self.stop(p)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_master(procs, port, env):
    """A rosmaster of our own, answering, with /use_sim_time set; returns its URI."""
    import rosgraph
    port = port or free_port()
    uri = f"http://localhost:{port}/"
    master_proc = procs.start("master", ["rosmaster", "--core", "-p", str(port), "-w", "3"], env=env)
    master = rosgraph.Master("/render_bag", master_uri=uri)
    deadline = time.time() + STARTUP_TIMEOUT
    while True:
        if master_proc.poll() is not None:
            raise RenderError(f"the ROS master on port {port} did not start: {procs.log_tail('master')}")
        try:
            master.getPid()
            break
        except Exception:
            if time.time() > deadline:
                raise RenderError(f"the ROS master on port {port} did not answer within {STARTUP_TIMEOUT:.0f} s")
            time.sleep(0.1)
    # The bag's stamps are simulated time: rviz must run on the /clock that rosbag play publishes.
    master.setParam("/use_sim_time", True)
    return uri, master


def start_display(procs, display, width, height):
    """Xvfb on `display` (or the first free one); returns ':N' once it accepts clients."""
    read_end, write_end = os.pipe()
    cmd = ["Xvfb"] + ([display] if display else []) + [
        "-screen", "0", f"{width}x{height}x24", "-nocursor", "-nolisten", "tcp", "-displayfd", str(write_end)]
    try:
        xvfb = procs.start("xvfb", cmd, pass_fds=(write_end,))
    finally:
        os.close(write_end)
    try:
        answer = b""
        deadline = time.time() + STARTUP_TIMEOUT
        while not answer.endswith(b"\n"):
            ready, _, _ = select.select([read_end], [], [], max(0.0, deadline - time.time()))
            chunk = os.read(read_end, 64) if ready else b""
            if not chunk:
                xvfb_status = xvfb.poll() if ready else None
                if ready or xvfb_status is not None:
                    xvfb.wait()
                    raise RenderError(f"the display {display or '(any free one)'} cannot start: Xvfb exited with "
                                      f"status {xvfb.returncode}: {procs.log_tail('xvfb')}")
                raise RenderError(f"the display {display or '(any free one)'} did not start within "
                                  f"{STARTUP_TIMEOUT:.0f} s")
            answer += chunk
    finally:
        os.close(read_end)
    return ":" + answer.decode().strip()


def wait_for_rviz(procs, rviz, master, topics):
    """Until rviz subscribes to every topic it will show (it has loaded its displays)."""
    deadline = time.time() + STARTUP_TIMEOUT
    while True:
        check_alive(procs, rviz, "rviz")
        try:
            _, subscribers, _ = master.getSystemState()
            subscribed = {topic for topic, nodes in subscribers if "/render_rviz" in nodes}
        except Exception:
            subscribed = set()
        if set(topics) <= subscribed:
            return
        if time.time() > deadline:
            raise RenderError(f"rviz did not subscribe to {', '.join(sorted(set(topics) - subscribed))} within "
                              f"{STARTUP_TIMEOUT:.0f} s")
        time.sleep(0.2)


def check_alive(procs, p, name):
    if p.poll() is not None:
        if p.returncode < 0:
            raise RenderError(f"{name} died (killed by {signal.Signals(-p.returncode).name})")
        raise RenderError(f"{name} died (exit status {p.returncode}): {procs.log_tail(name)}")


def start_capture(procs, display, width, height, fps, path):
    """ffmpeg grabbing the display to a lossless file whose timestamps are wall-clock time."""
    cmd = ["ffmpeg", "-nostdin", "-hide_banner", "-loglevel", "error", "-f", "x11grab", "-draw_mouse", "0",
           "-framerate", str(fps), "-video_size", f"{width}x{height}", "-i", display + ".0",
           "-copyts", "-c:v", "libx264rgb", "-preset", "ultrafast", "-qp", "0", "-flush_packets", "1", "-y", path]
    capture = procs.start("capture", cmd)
    deadline = time.time() + STARTUP_TIMEOUT
    while not (os.path.exists(path) and os.path.getsize(path) > 0):
        check_alive(procs, capture, "capture")
        if time.time() > deadline:
            raise RenderError(f"ffmpeg did not start capturing {display} within {STARTUP_TIMEOUT:.0f} s")
        time.sleep(0.1)
    return capture


def start_player(procs, args, contents, first, span, topics, env, rviz):
    """rosbag play of `span` seconds of the bag from bag time `first`, paused at its first message
    once rviz has connected to every topic it plays."""
    cmd = ["rosbag", "play", "--clock", "--pause", "--rate", repr(args.speed), "--start",
           repr(max(0.0, first - contents.start)), "--duration", repr(span), "--wait-for-subscribers", "--delay",
           "0.5"] + contents.parts + ["--topics"] + topics
    player = procs.start("play", cmd, env=env, stdout=subprocess.PIPE, stdin=subprocess.PIPE)
    read_until(procs, player, rviz, b"[PAUSED", STARTUP_TIMEOUT)
    return player


def read_until(procs, player, rviz, pattern, timeout, times=1):
    """Reads rosbag play's output until `pattern` appears `times` times in what it prints from now on."""
    deadline, buffered = time.time() + timeout, b""
    while buffered.count(pattern) < times:
        ready, _, _ = select.select([player.stdout], [], [], 0.2)
        chunk = os.read(player.stdout.fileno(), 4096) if ready else b""
        if ready and not chunk:
            player.wait()
            raise RenderError(f"rosbag play failed (exit status {player.returncode}): {procs.log_tail('play')}")
        buffered = (buffered + chunk)[-16384:]
        check_alive(procs, rviz, "rviz")
        if time.time() > deadline:
            raise RenderError(f"rosbag play did not answer within {timeout:.0f} s")


def warm_up(procs, player, rviz, messages):
    """Steps the paused player through the first instant's messages (an 's' on its stdin each, as
    on a terminal) and gives rviz WARM_UP seconds to build its scene: the first picture it draws
    takes it far longer than the next ones, and the video would miss the run's start."""
    for _ in range(messages):
        player.stdin.write(b"s")
        player.stdin.flush()
        # Paused, it prints a line every 0.1 s after reading its stdin: the second line after
        # the 's' comes after the step (one character per step: the rest would wait in its buffer).
        read_until(procs, player, rviz, b"[PAUSED", 10.0, times=2)
    deadline = time.time() + WARM_UP
    while time.time() < deadline:
        check_alive(procs, rviz, "rviz")
        time.sleep(0.05)


def replay(procs, args, player, first, span, rviz, capture, progress):
    """Resumes the paused player (a space on its stdin) and follows it to its end; returns the
    wall-clock time of bag time `first`.

    rosbag play maps bag time to wall time when it resumes: bag time t is published at
    W0 + (t - first) / speed. Each of its progress lines (bag time t, read at wall time w, a
    little after it was printed) bounds W0 from above, and the smallest bound is the closest."""
    player.stdin.write(b" ")
    player.stdin.flush()
    started, buffered = float("inf"), b""
    bag_time = re.compile(rb"\[RUNNING\]\s+Bag Time:\s+([0-9.]+)")
    while True:
        ready, _, _ = select.select([player.stdout], [], [], 0.5)
        chunk = os.read(player.stdout.fileno(), 4096) if ready else b""
        if ready and not chunk:
            break  # rosbag play ended
        seen = time.time()
        buffered += chunk
        times = [float(t) for t in bag_time.findall(buffered)]
        if times:
            started = min([started] + [seen - (t - first) / args.speed for t in times])
            progress((times[-1] - first) / span)
            buffered = buffered[buffered.rfind(b"[RUNNING]") + 1:]
        buffered = buffered[-4096:]
        check_alive(procs, rviz, "rviz")
        check_alive(procs, capture, "capture")
    player.wait()
    if player.returncode != 0 or started == float("inf"):
        raise RenderError(f"rosbag play failed (exit status {player.returncode}): {procs.log_tail('play')}")
    return started


def video_frames(seconds, speed, fps):
    """How many frames show `seconds` of the run at `speed`: one every 1/fps [s] of video from the
    first instant's picture, to the first at or after the last instant (so the last frame shows
    it; a thousandth of a frame of rounding aside)."""
    return math.ceil(seconds / speed * fps - 1e-3) + 1


def encode(capture_path, offset, frames, outs, fps):
    """The final videos: `frames` frames at `fps` from the capture's frame `offset` seconds into it
    on (the first at 0 s: a capture frame a little after `offset` is not pushed to the next
    frame's slot, which would leave the video's first slot empty and drop its last picture)."""
    for out in outs:
        if out.lower().endswith(".gif"):
            codec = ["-filter_complex", "[0:v]setpts=PTS-STARTPTS,split[a][b];[a]palettegen=stats_mode=diff[p];"
                     "[b][p]paletteuse=dither=none", "-loop", "0"]
        else:
            codec = ["-vf", "setpts=PTS-STARTPTS", "-c:v", "libx264", "-preset", "veryfast", "-crf", "23", "-pix_fmt",
                     "yuv420p", "-movflags", "+faststart"]
        # The input ends a frame after the cut: the GIF's palette is of the cut's pictures.
        cmd = ["ffmpeg", "-nostdin", "-hide_banner", "-loglevel", "error", "-ss", f"{offset:.3f}", "-t",
               f"{(frames + 1) / fps:.3f}", "-i", capture_path, "-r", str(fps), "-frames:v", str(frames)] + codec + [
               "-y", out]
        result = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True)
        if result.returncode != 0:
            lines = result.stderr.decode(errors="replace").strip().splitlines()
            raise RenderError(f"ffmpeg could not write {out}: {lines[-1] if lines else 'exit status %d' % result.returncode}")


def first_drawn(path, capture_start, since, width, height):
    """Wall-clock time of the first captured frame from `since` on that differs from the picture
    before `since`; `since` itself if none does within LATENCY_MAX."""
    import numpy as np
    # passthrough: one picture per captured frame, paired with showinfo's stamps (rawvideo's
    # default constant rate repeats a picture where x11grab skipped frames and shifts the pairs).
    cmd = ["ffmpeg", "-nostdin", "-hide_banner", "-loglevel", "info", "-ss", f"{max(0.0, since - capture_start - 0.5):.3f}",
           "-t", f"{LATENCY_MAX + 0.5:.3f}", "-i", path, "-copyts", "-vf", "showinfo", "-fps_mode", "passthrough",
           "-f", "rawvideo", "-pix_fmt", "gray", "-"]
    result = subprocess.run(cmd, capture_output=True, start_new_session=True)
    # showinfo's pts_time is rounded; pts is exact, in the time base it states first.
    base = re.search(rb"time_base:\s*(\d+)/(\d+)", result.stderr)
    if not base:
        return since
    stamps = [int(t) * int(base[1]) / int(base[2]) for t in re.findall(rb"\bn:\s*\d+\s+pts:\s*(\d+)", result.stderr)]
    frames = np.frombuffer(result.stdout, dtype=np.uint8)
    count = min(len(stamps), frames.size // (width * height))
    frames = frames[:count * width * height].reshape(count, height, width)
    before = [k for k in range(count) if stamps[k] < since]
    if not before:
        return since
    reference = frames[before[-1]]
    drawn = [stamps[k] for k in range(before[-1] + 1, count) if np.any(frames[k] != reference)]
    return drawn[0] if drawn else since


def capture_start(path):
    """Wall-clock time of the capture's first frame (x11grab stamps frames with it; -copyts keeps it)."""
    result = subprocess.run(["ffprobe", "-v", "error", "-show_entries", "format=start_time", "-of",
                             "default=noprint_wrappers=1:nokey=1", path], capture_output=True, text=True)
    try:
        return float(result.stdout.strip())
    except ValueError:
        raise RenderError(f"ffprobe cannot read the capture: {result.stderr.strip() or 'no start time'}")


def package_path():
    import rospkg
    try:
        return rospkg.RosPack().get_path("variational_formation")
    except rospkg.ResourceNotFound:
        return os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def render(args, procs, tmp, progress):
    contents = BagContents(args.bags)
    prefix, markers, odometry, topics = choose_topics(contents, args.ns)
    run = RunSpan(contents, prefix + "/formation/status", markers, args.start, args.end)
    frames = video_frames(run.end - run.start, args.speed, args.fps)
    if run.on_wall_time:
        # A timed or robots bag: replay a copy on the run's clock (variational_formation/run_clock.py).
        copy = os.path.join(tmp, "run.bag")
        run.write_on_run_time(contents, topics, copy)
        contents = BagContents([copy])
        # rosbag record may have joined a topic (the world's markers) only after the shown span.
        topics = [t for t in topics if t in contents.topics]
    first, span = run.first, run.last - run.first
    scene = Scene(contents, markers, first, first + span)
    config = os.path.join(tmp, "formation.rviz")
    with open(config, "w") as f:
        f.write(rviz_config(os.path.join(package_path(), "config", "formation.rviz"), markers, odometry, scene, args,
                            world_markers(contents, prefix)))
    env = dict(os.environ, ROS_HOSTNAME="localhost", ROS_LOG_DIR=os.path.join(tmp, "log"))
    env.pop("ROS_IP", None)
    uri, master = start_master(procs, args.port, env)
    env["ROS_MASTER_URI"] = uri
    display = start_display(procs, args.display, args.width, args.height)
    env["DISPLAY"] = display
    rviz = procs.start("rviz", ["rviz", "-d", config, "--fullscreen", "__name:=render_rviz"], env=env)
    wait_for_rviz(procs, rviz, master, [t for t in topics if t != "/tf_static"])
    player = start_player(procs, args, contents, first, span, topics, env, rviz)
    timings = {"start-up": time.time()}
    capture_path = os.path.join(tmp, "capture.mkv")
    capture = start_capture(procs, display, args.width, args.height, args.fps, capture_path)
    count, second = first_instant(contents, topics, first)
    warm_up(procs, player, rviz, count)
    started = replay(procs, args, player, first, span, rviz, capture, progress)
    played = frames / args.fps
    # The capture must hold the last picture, drawn up to LATENCY_MAX late.
    while time.time() < started + played + LATENCY_MAX + 0.2:
        time.sleep(0.05)
    procs.stop(capture, first_signal=signal.SIGINT, timeout=20.0)  # SIGINT: ffmpeg closes the file
    if capture.returncode not in (0, 255, -signal.SIGINT):
        raise RenderError(f"ffmpeg's capture failed (exit status {capture.returncode}): {procs.log_tail('capture')}")
    timings["replay"] = time.time()
    progress(None)
    start_time = capture_start(capture_path)
    # rviz draws late: the first change on screen after the replay resumed shows the second
    # instant, published (second - first) / speed after it. The video starts that much earlier,
    # on the picture of the first instant, half a frame early so that the seek keeps it.
    shown = (second - first) / args.speed if second is not None else 0.0
    latency = min(LATENCY_MAX, max(0.0, first_drawn(capture_path, start_time, started + shown, args.width, args.height)
                                   - started - shown))
    offset = started + latency - start_time - 0.5 / args.fps
    encode(capture_path, max(0.0, offset), frames, args.out, args.fps)
    timings["encoding"] = time.time()
    return run.start, run.end, played, timings


def main():
    args = parse_args()
    tty = sys.stdout.isatty()

    def progress(fraction):
        if tty and fraction is not None:
            print(f"\rrender_bag: replaying {min(max(fraction, 0.0), 1.0):6.1%}", end="", flush=True)
        elif tty:
            print("\rrender_bag: encoding          ", end="", flush=True)

    def interrupt(signum, _frame):
        raise Interrupted(signal.Signals(signum).name)

    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, interrupt)
    tmp = tempfile.mkdtemp(prefix="render_bag_")
    procs = Processes(tmp)
    status, message = 0, None
    wall = time.time()
    try:
        start, end, played, timings = render(args, procs, tmp, progress)
    except RenderError as e:
        status, message = 1, str(e)
    except Interrupted as e:
        status, message = 130, f"interrupted ({e}); every process it started is stopped"
    finally:
        # A second signal must not stop the clean-up half way.
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
            signal.signal(sig, signal.SIG_IGN)
        procs.stop_all()
        shutil.rmtree(tmp, ignore_errors=True)
        if tty:
            print("\r" + " " * 40 + "\r", end="", flush=True)
    if message:
        print(f"render_bag: error: {' '.join(message.split())}", file=sys.stderr)
        sys.exit(status)
    print(f"render_bag: wrote {', '.join(args.out)}: {start:.2f}..{end:.2f} s of the run at speed {args.speed:g} in "
          f"{played:.2f} s of video; {time.time() - wall:.1f} s wall time ("
          + ", ".join(f"{stage} {t - previous:.1f} s" for (stage, t), previous in
                      zip(timings.items(), [wall] + list(timings.values()))) + ")")


if __name__ == "__main__":
    main()
