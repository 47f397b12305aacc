"""Shared by the rostests: the scenario, `simulate`'s trajectory, a recorded bag, and the checks
every recorded run must pass (every agent's every step, bit for bit equal to simulate, stamps
equal to the simulated time, the status of every step, the Noether laws)."""
import csv
import math
import os
import subprocess
import tempfile
import threading
import time
import traceback

import xmlrpc.client

import rosbag
import rosgraph
import rospy
import rospkg
import yaml

PKG = "variational_formation"


def reported_setup(cls):
    """Class decorator for a rostest's TestCase: an exception in setUpClass fails every test with
    its message and the line it came from. Left alone, unittest counts it as an error outside
    any test, and rosunit's XML keeps neither the message nor the traceback."""
    set_up_class = cls.__dict__["setUpClass"].__func__
    tear_down_class = cls.__dict__["tearDownClass"].__func__ if "tearDownClass" in cls.__dict__ else None
    set_up = cls.setUp

    def guarded_set_up_class(klass):
        klass.setup_error = None
        try:
            set_up_class(klass)
        except Exception as e:  # reported by every test below
            frame = traceback.extract_tb(e.__traceback__)[-1]
            klass.setup_error = (f"setUpClass failed at {os.path.basename(frame.filename)}:{frame.lineno}: "
                                 f"{type(e).__name__}: {e}")

    def guarded_tear_down_class(klass):
        try:
            tear_down_class(klass)
        except Exception:
            if klass.setup_error is None:
                raise  # after a failed setUpClass, attributes it never set are no news

    def checked_set_up(self):
        if type(self).setup_error:
            self.fail(type(self).setup_error)
        set_up(self)

    cls.setUpClass = classmethod(guarded_set_up_class)
    if tear_down_class:
        cls.tearDownClass = classmethod(guarded_tear_down_class)
    cls.setUp = checked_set_up
    return cls


def scenario_path(name):
    if "/" in name or name.endswith(".yaml"):
        return name
    return os.path.join(rospkg.RosPack().get_path(PKG), "config", name + ".yaml")


def load_scenario(path):
    with open(path) as f:
        s = yaml.safe_load(f)
    s["n"] = len(s["agents"])
    s["neighbours"] = {i: sorted({b for a, b in s["edges"] if a == i} | {a for a, b in s["edges"] if b == i})
                       for i in range(s["n"])}
    return s


def simulate(path, commands=None):
    """{(agent, step): [coordinates]} of `simulate` (with `--commands FILE` if given), as printed
    (%.17g round-trips a double)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "traj.csv")
        subprocess.run(["rosrun", PKG, "simulate", "--scenario", path, "--out", out] +
                       (["--commands", commands] if commands else []), check=True)
        with open(out) as f:
            rows = list(csv.DictReader(f))
    d = int(load_scenario(path)["dimension"])
    return {(int(r["agent"]), int(r["step"])): [float(r[c]) for c in "xyz"[:d]] for r in rows}


def node_pid(name, timeout=20.0):
    """The process id of a running node, asked of the node itself (as `rosnode info` does)."""
    master = rosgraph.Master("/vf_rostest")
    end = time.time() + timeout
    while time.time() < end:
        try:
            return xmlrpc.client.ServerProxy(master.lookupNode(name)).getPid("/vf_rostest")[2]
        except Exception:
            time.sleep(0.05)
    raise AssertionError(f"{name} did not come up")


def wait_for_result(path, timeout):
    """The monitor's result file once the run is over ({} if it is not within `timeout`; read
    once with timeout 0)."""
    end = time.time() + timeout
    while True:
        try:
            with open(path) as f:
                result = yaml.safe_load(f) or {}
            if result.get("result") not in (None, "running"):
                return result
        except OSError:
            pass
        if time.time() >= end:
            return {}
        time.sleep(0.2)


# The agents' colours in the markers (src/ros/markers.cpp, agentColour), as RGB in [0, 1].
PALETTE = [(0.90, 0.10, 0.10), (0.10, 0.45, 0.90), (0.10, 0.75, 0.20), (0.95, 0.60, 0.05),
           (0.60, 0.20, 0.80), (0.05, 0.80, 0.80)]


def agent_colour_pixels(image):
    """Per colour of PALETTE, how many pixels of an RGB image in [0, 1] have its hue, saturated
    and bright enough to be a sphere or trail drawn by rviz."""
    import colorsys

    import matplotlib.colors
    import numpy as np
    hsv = matplotlib.colors.rgb_to_hsv(image[:, :, :3])
    counts = []
    for rgb in PALETTE:
        hue = colorsys.rgb_to_hsv(*rgb)[0]
        distance = np.minimum(abs(hsv[:, :, 0] - hue), 1 - abs(hsv[:, :, 0] - hue))
        counts.append(int(((distance < 0.02) & (hsv[:, :, 1] > 0.5) & (hsv[:, :, 2] > 0.25)).sum()))
    return counts


def bag_parts(bag_path):
    """The files of one recording: <name>.bag, then <name>_1.bag, ... while they exist (a long run
    is split by record_split_size)."""
    parts, stem = [bag_path], bag_path[:-len(".bag")] if bag_path.endswith(".bag") else bag_path
    while os.path.exists(f"{stem}_{len(parts)}.bag"):
        parts.append(f"{stem}_{len(parts)}.bag")
    return parts


class Recording:
    """Everything a bag of formation.launch record:=true holds, by agent and step."""

    def __init__(self, bag_path, ns="/formation"):
        self.states, self.status, self.tf, self.tf_times, self.topics = {}, {}, {}, {}, set()
        self.marker_stamps = []  # one per marker array
        self.commands = []  # (bag time, FormationCommands): the issued commands so far, at the step the newest applies
        self.bag_times = []
        # Messages whose bag time is earlier than the one before (Python's rosbag yields them in
        # write order across chunks, so a late write shows up here).
        self.out_of_order = []
        last = None
        for part in bag_parts(bag_path):
            with rosbag.Bag(part) as bag:
                for topic, msg, t in bag.read_messages():
                    if last is not None and t < last:
                        self.out_of_order.append((topic, t.to_sec(), last.to_sec()))
                    last = t
                    self.topics.add(topic)
                    if topic.startswith(ns + "/agent_") and topic.endswith("/state"):
                        self.states.setdefault((msg.id, msg.step), []).append(msg)
                        self.bag_times.append((t, msg.header.stamp))
                    elif topic == ns + "/status":
                        self.status.setdefault(msg.step, []).append(msg)
                    elif topic == ns + "/command":
                        self.commands.append((t.to_sec(), msg))
                    elif topic == ns + "/markers":
                        self.marker_stamps.append(msg.markers[0].header.stamp.to_sec() if msg.markers else -1.0)
                    elif topic == "/tf":
                        for x in msg.transforms:
                            self.tf.setdefault(x.child_frame_id, []).append(x)
                            self.tf_times.setdefault(x.child_frame_id, []).append(t.to_sec())


class RunChecks:
    """Mix-in for unittest.TestCase: the checks of one recorded run."""

    def check_each_step_once(self, rec, n, steps):
        """Every (agent, step) state and every status is there once, whatever arrived twice (the
        recorder writes a repeat never), and the bag is in time order, whatever arrived late (the
        recorder writes whole steps in order)."""
        missing = [(i, k) for i in range(n) for k in range(steps + 1) if (i, k) not in rec.states]
        self.assertEqual(missing[:10], [], f"{len(missing)} agent states missing")
        twice = sorted(key for key, msgs in rec.states.items() if len(msgs) != 1)
        self.assertEqual(twice[:10], [], f"{len(twice)} states recorded more than once")
        self.assertEqual(len(rec.states), n * (steps + 1), "states beyond the last step")
        self.assertEqual(sorted(rec.status), list(range(steps + 1)), "status of every step")
        self.assertEqual([k for k, msgs in rec.status.items() if len(msgs) != 1], [], "statuses recorded twice")
        self.assertEqual(rec.out_of_order[:5], [], f"{len(rec.out_of_order)} messages out of time order")

    def check_equals_simulate(self, rec, scenario, expected):
        """Every (agent, step) once, and each position equal to `expected` (simulate's) bit for bit."""
        self.check_each_step_once(rec, scenario["n"], int(scenario["steps"]))
        differ = sorted(key for key, msgs in rec.states.items() if any(list(m.position) != expected[key] for m in msgs))
        self.assertEqual(differ[:5], [], f"{len(differ)} recorded states differ from simulate")

    def check_recording(self, rec, scenario, expected, ns="/formation", marker_every=0):
        """`marker_every` as the run's `~marker_every`: 0 (the default) is one step in every 0.02 s of
        simulated time (doc/ros_api.md, the monitor's `~marker_every`)."""
        n, steps, h = scenario["n"], int(scenario["steps"]), float(scenario["time_step"])
        self.check_each_step_once(rec, n, steps)
        mismatches = 0
        for (i, k), msgs in rec.states.items():
            for m in msgs:
                if list(m.position) != expected[(i, k)]:
                    mismatches += 1
                # The stamp is the simulated time t_k, to the nanosecond.
                self.assertLess(abs(m.header.stamp.to_sec() - k * h), 1.01e-9 + 1e-15 * k * h)
                self.assertAlmostEqual(m.time, k * h, delta=1e-12 * (1 + k * h))
        self.assertEqual(mismatches, 0, f"{mismatches} recorded positions differ from simulate")
        # Markers of every marker_every-th step and of the last, once each (the monitor republishes
        # those the recorder has not confirmed).
        every = marker_every or max(1, math.ceil(0.02 / h - 1e-9))
        self.assertEqual(sorted(round(t / h) for t in rec.marker_stamps),
                         [k for k in range(steps + 1) if k % every == 0 or k == steps])
        # tf: every agent's frame, prefixed by the namespace, at every step, stamped t_k.
        prefix = ns.lstrip("/") + "/" if ns.strip("/") else ""
        for i in range(n):
            frames = rec.tf.get(f"{prefix}agent_{i}", [])
            self.assertEqual(len(frames), steps + 1, f"tf of {prefix}agent_{i}")
            for k, t in enumerate(frames):
                self.assertEqual(t.header.frame_id, "world")
                if t.transform.translation.x != expected[(i, k)][0]:  # says where the frames went
                    x = expected[(i, k)][0]
                    self.fail(f"tf of agent {i}: frame {k} of the bag, stamped {t.header.stamp.to_sec()!r}, holds "
                              f"the x of steps {[m for m in range(steps + 1) if expected[(i, m)][0] == t.transform.translation.x]}; "
                              f"step {k}'s x is in frames "
                              f"{[(j, f.header.stamp.to_sec()) for j, f in enumerate(frames) if f.transform.translation.x == x]}; "
                              f"bag times of frames {max(k - 2, 0)}..{k + 2}: {rec.tf_times[t.child_frame_id][max(k - 2, 0):k + 3]}")
        if scenario.get("manoeuvre"):
            self.check_no_noether_prediction(rec)
        else:
            self.check_noether(rec)

    def check_no_noether_prediction(self, rec):
        """Under a commanded motion the unforced run's Noether predictions do not hold: NaN."""
        for k, (s,) in rec.status.items():
            self.assertTrue(math.isnan(s.linear_momentum_predicted.x), f"step {k}")
            self.assertTrue(math.isnan(s.angular_momentum_predicted.z), f"step {k}")

    def check_noether(self, rec):
        for k, (s,) in rec.status.items():
            for x, pred in ((s.linear_momentum, s.linear_momentum_predicted),
                            (s.angular_momentum, s.angular_momentum_predicted)):
                scale = max(1.0, math.sqrt(pred.x ** 2 + pred.y ** 2 + pred.z ** 2))
                err = math.sqrt((x.x - pred.x) ** 2 + (x.y - pred.y) ** 2 + (x.z - pred.z) ** 2)
                self.assertLess(err / scale, 1e-9, f"step {k}")


def goal_pose(x, y, yaw, frame="world"):
    """A geometry_msgs/PoseStamped at (x, y) facing `yaw` about z, as rviz's 2D Nav Goal sends."""
    from geometry_msgs.msg import PoseStamped
    p = PoseStamped()
    p.header.frame_id = frame
    p.pose.position.x, p.pose.position.y = x, y
    p.pose.orientation.z, p.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return p


def wrap(a):
    """An angle in (-pi, pi]."""
    return math.atan2(math.sin(a), math.cos(a))


def formation_pose(q, desired):
    """(x, y, yaw) of positions q: the centroid, and the rotation of the best 2D fit of the desired
    shape onto q (Kabsch), computed here, not by the package."""
    n = len(q)
    c = [sum(p[0] for p in q) / n, sum(p[1] for p in q) / n]
    dc = [sum(p[0] for p in desired) / n, sum(p[1] for p in desired) / n]
    cross = sum((a[0] - dc[0]) * (b[1] - c[1]) - (a[1] - dc[1]) * (b[0] - c[0]) for a, b in zip(desired, q))
    dot = sum((a[0] - dc[0]) * (b[0] - c[0]) + (a[1] - dc[1]) * (b[1] - c[1]) for a, b in zip(desired, q))
    return c[0], c[1], math.atan2(cross, dot)


class AgentStates:
    """Every agent's position at every step, from their own state topics, and the formation's pose
    (formation_pose) at the newest step that every agent has reported."""

    def __init__(self, ns, scenario):
        from variational_formation_msgs.msg import AgentState
        self.n = scenario["n"]
        self.desired = [a["desired_position"] for a in scenario["agents"]]
        self.states = {}
        self.subs = [rospy.Subscriber(f"{ns}/agent_{i}/state", AgentState, self.on_state, queue_size=500)
                     for i in range(self.n)]

    def on_state(self, msg):
        self.states.setdefault(msg.step, {})[msg.id] = list(msg.position)

    def complete(self):
        """The steps every agent has reported, in order."""
        return sorted(k for k, got in list(self.states.items()) if len(got) == self.n)

    def pose_now(self):
        k = self.complete()[-1]
        return formation_pose([self.states[k][i] for i in range(self.n)], self.desired)

    def unregister(self):
        for sub in self.subs:
            sub.unregister()


def recorded_with_commands(out, path, timeout):
    """A recorded run of the scenario at `path` in `out` once over: its result file (waited for up
    to `timeout` s), its bag, its commands file and `simulate`'s states under that file ({} if
    there is none)."""
    name = os.path.splitext(os.path.basename(path))[0]
    result = wait_for_result(os.path.join(out, name + ".result.yaml"), timeout)
    commands = os.path.join(out, name + ".commands.csv")
    expected = simulate(path, commands) if os.path.exists(commands) else {}
    return result, os.path.join(out, name + ".bag"), commands, expected


def wait_until(condition, timeout, poll=0.01):
    """Whether `condition()` holds within `timeout` s, looked at every `poll` s: a wait on the
    condition a test asserts next, instead of a sleep that guesses how long it takes."""
    end = time.time() + timeout
    while not condition():
        if time.time() >= end:
            return False
        time.sleep(poll)
    return True


class StepWatcher:
    """The newest completed step on the monitor's status topic, and a wait for a given one. Fault
    tests extend it with what else they follow (each agent's states, log lines)."""

    def __init__(self, topic="/formation/status", queue_size=10000, poll=0.01):
        from variational_formation_msgs.msg import FormationStatus
        self.lock = threading.Lock()
        self.step = -1
        self.poll = poll  # s between two looks while waiting
        self.subs = [rospy.Subscriber(topic, FormationStatus, self.on_status, queue_size=queue_size)]

    def on_status(self, msg):
        with self.lock:
            self.step = max(self.step, msg.step)

    def wait_for_step(self, step, timeout=60.0):
        """Whether the status reaches `step` within `timeout` s."""
        return wait_until(lambda: self.step >= step, timeout, self.poll)

    def unregister(self):
        for sub in self.subs:
            sub.unregister()


class Steering:
    """Sends the formation in `ns` one velocity command and later a stop (zero Twist), as a
    foreign node would (formation/cmd_vel), and notes the formation's centroid at both moments,
    computed with the agents' states, to check how far it went."""

    def __init__(self, ns, n):
        from geometry_msgs.msg import Twist
        from variational_formation_msgs.msg import AgentState
        self.Twist = Twist
        self.newest = {}
        self.subs = [rospy.Subscriber(f"{ns}/agent_{i}/state", AgentState, self.on_state, queue_size=10)
                     for i in range(n)]
        self.n = n
        self.pub = rospy.Publisher(f"{ns}/cmd_vel", Twist, queue_size=10)
        end = time.time() + 30
        while self.pub.get_num_connections() == 0 and time.time() < end:
            time.sleep(0.05)
        assert self.pub.get_num_connections(), f"nobody subscribes to {ns}/cmd_vel"

    def on_state(self, msg):
        self.newest[msg.id] = list(msg.position)

    def centroid(self):
        assert len(self.newest) == self.n, f"states of {sorted(self.newest)} only"
        points = list(self.newest.values())
        return [sum(p[c] for p in points) / self.n for c in range(len(points[0]))]

    def send(self, vx, vy, wz=0.0):
        t = self.Twist()
        t.linear.x, t.linear.y, t.angular.z = vx, vy, wz
        self.pub.publish(t)
        return self.centroid()

    def close(self):
        for s in self.subs:
            s.unregister()

