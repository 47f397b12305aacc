#!/usr/bin/python3
"""rostest (launch.test): whole launches as a user runs them (roslaunch and run_formation.sh in
subprocesses, on the test's master), with real faults.

- A recorded run through run_formation.sh succeeds (exit 0) and rviz renders its bag.
- The result file and the monitor's last line say whether and when the formation converged; a run
  that never formed says 'not converged' with its final error, and fails if its scenario requires
  convergence.
- Bad input (a missing scenario, kappa -1, a bad edge, a bad order or rate, an unwritable
  output_dir) ends the launch with one line naming the cause, and run_formation.sh exits non-zero.
- Without respawn, an agent killed with SIGKILL, or with `rosnode kill`, ends the run: the monitor's line names it,
  the result file says failed, run_formation.sh exits non-zero.
- Agents started first, each by its own agent.launch (as on robots), with stray subscribers on
  their topics, wait for the monitor and recorder started later (agents:=false): the bag is still
  complete and equals simulate. A monitor started again against those agents, whose run is over,
  says so in one line and reports a failure, not a success it did not witness.
- agent.launch manager:=NAME: three agents loaded as nodelets into a manager started by hand,
  three as nodes, run with formation.launch agents:=false agent_manager:=NAME: equals simulate.
- Flow control: while the monitor is stopped (SIGSTOP), no agent runs past the allowed step.
- A bad node parameter is one ROS_FATAL line naming it and exit status 2.
- A diverging scenario ends the run within seconds, with one line naming the agent and the step
  (the step at which simulate's trajectory of that agent stops being finite).
- An unbounded recorded run with a small size limit splits its bag and stops recording at the
  limit, while the run goes on.
"""
import csv
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import matplotlib

matplotlib.use("Agg")
import matplotlib.image  # noqa: E402
import numpy as np  # noqa: E402
import rospy  # noqa: E402
import rostest  # noqa: E402
import yaml  # noqa: E402
from variational_formation_msgs.msg import AgentState, RunProgress  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402

PKG = vf_rostest.PKG
SCENARIO = "hexagon"


def run_formation(*args, timeout=120):
    return subprocess.run(["rosrun", PKG, "run_formation.sh", *args], capture_output=True, text=True,
                          timeout=timeout)


def start(cmd):
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            start_new_session=True)


@vf_rostest.reported_setup
class LaunchTest(unittest.TestCase, vf_rostest.RunChecks):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("launch_test")
        cls.tmp = tempfile.mkdtemp(prefix="vf_launch_test_")
        cls.path = vf_rostest.scenario_path(SCENARIO)
        cls.scenario = vf_rostest.load_scenario(cls.path)
        cls.recording = run_formation(f"scenario:={SCENARIO}", "record:=true", f"output_dir:={cls.tmp}")
        cls.bag = os.path.join(cls.tmp, SCENARIO + ".bag")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def scenario_variant(self, file_name, **fields):
        s = {k: v for k, v in self.scenario.items() if k not in ("n", "neighbours")}
        s.update(fields)
        path = os.path.join(self.tmp, file_name + ".yaml")
        with open(path, "w") as f:
            yaml.safe_dump(s, f)
        return path

    def test_recorded_run_succeeds(self):
        self.assertEqual(self.recording.returncode, 0, self.recording.stderr[-3000:])
        with open(os.path.join(self.tmp, SCENARIO + ".result.yaml")) as f:
            self.assertEqual(yaml.safe_load(f)["result"], "succeeded")

    def test_result_says_whether_and_when_the_formation_converged(self):
        """The recorded run converged and its result says at which step; a run too short to form
        succeeds but says 'not converged' with the final error, in the result file and the monitor's
        last line; the same run fails when its scenario has require_convergence: true."""
        with open(os.path.join(self.tmp, SCENARIO + ".result.yaml")) as f:
            done = yaml.safe_load(f)
        self.assertEqual(done["result"], "succeeded")
        self.assertRegex(done["formation"], r"^converged to the desired shape at step \d+ \(t = [0-9.]+ s\)$")
        self.assertEqual(int(done["formation"].split()[7]), done["converged_step"])
        self.assertLess(done["shape_error"], 0.01 * 3.0)  # every pair within 1 % (the hexagon's side is 3 m)
        # The strict variant's own name holds what YAML would misread unescaped: the result file
        # quotes and escapes it (yamlQuoted), so it reads back as written.
        odd_name = 'short "strict": C:\\runs\\new #2 \\'
        for name, strict in (("short", False), ("short_strict", True)):
            fields = dict(steps=20, require_convergence=True, name=odd_name) if strict else dict(steps=20)
            path = self.scenario_variant(name, **fields)
            out = os.path.join(self.tmp, name)
            run = run_formation(f"scenario:={path}", f"output_dir:={out}")
            with open(os.path.join(out, name + ".result.yaml")) as f:
                result = yaml.safe_load(f)
            self.assertTrue(result["formation"].startswith("not converged (final max distance error "), result)
            self.assertEqual(result["converged_step"], -1)
            self.assertGreater(result["final_max_distance_error"], 0.0)
            if strict:
                self.assertNotEqual(run.returncode, 0, run.stdout[-3000:])
                self.assertEqual(result["scenario"], odd_name)
                self.assertEqual(result["result"], "failed")
                self.assertIn("the formation did not converge", result["reason"])
                self.assertIn("requires it (require_convergence: true)", run.stderr)
            else:
                self.assertEqual(run.returncode, 0, run.stdout[-3000:] + run.stderr[-2000:])
                self.assertEqual(result["result"], "succeeded")
                last = [line for line in run.stdout.splitlines() if "monitor: run succeeded" in line]
                self.assertTrue(last and "formation not converged (final max distance error" in last[-1],
                                run.stdout[-3000:])
                self.assertIn("the formation did not converge", run.stderr)

    def test_bad_input_is_one_line_and_a_failure(self):
        bad_edge = self.scenario_variant("bad_edge", edges=list(self.scenario["edges"]) + [[0, 9]])
        cases = (
            ([f"scenario:={self.tmp}/missing.yaml"], "make_agents_launch: error:", "cannot open the scenario file"),
            ([f"scenario:={self.scenario_variant('negative_kappa', kappa=-1.0)}"], "make_agents_launch: error:",
             "kappa: must be finite and >= 0, got -1"),
            ([f"scenario:={bad_edge}"], "make_agents_launch: error:", "edges[9]: agent 9 does not exist"),
            ([f"scenario:={SCENARIO}", "order:=sideways"], "make_agents_launch: error:", "order: invalid choice"),
            ([f"scenario:={SCENARIO}", "rate:=-1"], "make_agents_launch: error:", "rate: must be a finite number >= 0"),
            ([f"scenario:={SCENARIO}", "nodelet:=true", "mode:=timed", "rate:=1"], "make_agents_launch: error:",
             "nodelet: only lockstep agents are nodelets"),
            ([f"scenario:={SCENARIO}", "nodelet:=true", "nodelet_threads:=-1"], "make_agents_launch: error:",
             "nodelet_threads: must be >= 0"),
            ([f"scenario:={SCENARIO}", "output_dir:=/etc/hostname/out"], "FATAL",
             "~result_file: cannot create the directory"),
        )
        for args, marker, words in cases:
            run = run_formation(*args, timeout=60)
            out = run.stdout + run.stderr
            # One line; a respawning node may print it again before the launch ends.
            lines = {re.sub(r"\[\d+\.\d+\]", "", line) for line in out.splitlines() if marker in line}
            self.assertNotEqual(run.returncode, 0, f"{args}: {out[-3000:]}")
            self.assertEqual(len(lines), 1, f"{args}: {out[-3000:]}")
            self.assertIn(words, lines.pop(), args)

    def check_killed_agent_fails_the_run(self, kill, victim):
        out = os.path.join(self.tmp, "killed")
        watcher = vf_rostest.StepWatcher(queue_size=1000, poll=0.02)
        run = start(["rosrun", PKG, "run_formation.sh", f"scenario:={SCENARIO}", "rate:=1", "respawn:=false",
                     f"output_dir:={out}"])
        try:
            self.assertTrue(watcher.wait_for_step(60, 30.0), "the run did not start")
            kill(victim)
            killed_at = time.time()
            log, _ = run.communicate(timeout=40)
            ended_after = time.time() - killed_at
        finally:
            watcher.unregister()
            if run.poll() is None:
                os.killpg(run.pid, signal.SIGINT)
                run.wait(timeout=30)
        self.assertNotEqual(run.returncode, 0, log[-3000:])
        failed = [line for line in log.splitlines() if "monitor: run failed at step" in line]
        self.assertEqual(len(failed), 1, log[-3000:])
        self.assertIn(victim, failed[0])
        with open(os.path.join(out, SCENARIO + ".result.yaml")) as f:
            result = yaml.safe_load(f)
        self.assertEqual(result["result"], "failed")
        self.assertIn(victim, result["reason"])
        self.assertLess(ended_after, 15.0, "the launch took too long to end after the kill")

    def test_agent_killed_with_sigkill_fails_the_run_naming_it(self):
        self.check_killed_agent_fails_the_run(lambda name: os.kill(vf_rostest.node_pid(name), signal.SIGKILL),
                                              "/formation/agent_3")

    def test_agent_ended_with_rosnode_kill_fails_the_run_naming_it(self):
        self.check_killed_agent_fails_the_run(
            lambda name: subprocess.run(["rosnode", "kill", name], capture_output=True, check=True),
            "/formation/agent_2")

    def test_agents_started_elsewhere_wait_for_the_monitor_and_recorder(self):
        out = os.path.join(self.tmp, "elsewhere")
        stray = [start(["rostopic", "echo", "-n", "1000000", f"/formation/agent_{i}/state"]) for i in (0, 1)]
        stray.append(start(["rostopic", "echo", "-n", "1000000", "/formation/status"]))
        agents = [start(["roslaunch", PKG, "agent.launch", f"id:={i}", f"scenario:={SCENARIO}"])
                  for i in range(self.scenario["n"])]
        logs = []
        try:
            # Until every agent is up (its latched step 0) and has waited long enough to say so.
            for i in range(self.scenario["n"]):
                rospy.wait_for_message(f"/formation/agent_{i}/state", AgentState, timeout=60)
            time.sleep(6.0)
            run = run_formation(f"scenario:={SCENARIO}", "agents:=false", "record:=true", f"output_dir:={out}")
            self.assertEqual(run.returncode, 0, run.stdout[-3000:] + run.stderr[-2000:])
            # A monitor started again against these agents did not witness their run: it says in
            # one line that the run is over, and reports no success.
            again_dir = os.path.join(self.tmp, "again")
            again = run_formation(f"scenario:={SCENARIO}", "agents:=false", f"output_dir:={again_dir}", timeout=90)
            self.assertNotEqual(again.returncode, 0, again.stdout[-3000:])
            over = [line for line in (again.stdout + again.stderr).splitlines()
                    if "belong to a run that is already over (it finished at step" in line]
            self.assertTrue(over, again.stdout[-3000:] + again.stderr[-2000:])
            self.assertNotIn("run succeeded", again.stdout + again.stderr)
            with open(os.path.join(again_dir, SCENARIO + ".result.yaml")) as f:
                result = yaml.safe_load(f)
            self.assertEqual(result["result"], "failed", result)
            self.assertIn("already over", result["reason"])
            for a in agents:  # the run is over: the agents idle until they are stopped, as on robots
                os.killpg(a.pid, signal.SIGINT)
                log, _ = a.communicate(timeout=30)
                logs.append(log)
        finally:
            for p in stray + agents:
                if p.poll() is None:
                    os.killpg(p.pid, signal.SIGINT)
                    p.wait(timeout=30)
        self.assertTrue(all("waiting for the monitor /formation/monitor to start the run" in log for log in logs),
                        logs[0][-2000:])
        rec = vf_rostest.Recording(os.path.join(out, SCENARIO + ".bag"))
        self.check_recording(rec, self.scenario, vf_rostest.simulate(self.path))

    def test_agents_loaded_into_a_manager_elsewhere_beside_agent_nodes(self):
        """agent.launch manager:=NAME: agents 0-2 are nodelets of a manager started by hand (as on
        a robot or host), agents 3-5 are nodes; they accept each other's states, and the run
        recorded by formation.launch agents:=false agent_manager:=NAME equals simulate."""
        out = os.path.join(self.tmp, "managed")
        manager = start(["rosrun", "nodelet", "nodelet", "manager", "__name:=host_b", "__ns:=formation"])
        agents = [start(["roslaunch", PKG, "agent.launch", f"id:={i}", f"scenario:={SCENARIO}",
                         "manager:=host_b" if i < 3 else "agent_manager:=host_b"])
                  for i in range(self.scenario["n"])]
        try:
            for i in range(self.scenario["n"]):
                msg = rospy.wait_for_message(f"/formation/agent_{i}/state", AgentState, timeout=60)
                # A nodelet's states carry its manager's name as caller id.
                self.assertEqual(msg._connection_header["callerid"],
                                 "/formation/host_b" if i < 3 else f"/formation/agent_{i}")
            run = run_formation(f"scenario:={SCENARIO}", "agents:=false", "record:=true", "agent_manager:=host_b",
                                f"output_dir:={out}")
            self.assertEqual(run.returncode, 0, run.stdout[-3000:] + run.stderr[-2000:])
            dropped = [int(k) for k in re.findall(r"(\d+) dropped", run.stdout + run.stderr)]
            self.assertTrue(dropped, run.stdout[-2000:])
            self.assertEqual(max(dropped), 0, run.stdout[-3000:])
        finally:
            for p in agents + [manager]:
                if p.poll() is None:
                    os.killpg(p.pid, signal.SIGINT)
                    p.wait(timeout=30)
        rec = vf_rostest.Recording(os.path.join(out, SCENARIO + ".bag"))
        self.check_recording(rec, self.scenario, vf_rostest.simulate(self.path))

    def test_agents_never_run_past_the_window_while_the_monitor_is_stopped(self):
        unbounded = self.scenario_variant("unbounded", steps=0)
        window = 40
        steps, allowed = {}, [0]

        def on_state(msg, i):
            if msg._connection_header.get("callerid") == f"/formation/agent_{i}":
                steps[i] = (max(steps.get(i, (-1, 0))[0], msg.step), time.time())

        def on_progress(msg):
            allowed[0] = max(allowed[0], msg.allowed_step)

        subs = [rospy.Subscriber(f"/formation/agent_{i}/state", AgentState, on_state, i, queue_size=100000)
                for i in range(self.scenario["n"])]
        subs.append(rospy.Subscriber("/formation/progress", RunProgress, on_progress, queue_size=1000))
        watcher = vf_rostest.StepWatcher(queue_size=1000, poll=0.02)
        out = os.path.join(self.tmp, "window")
        run = start(["rosrun", PKG, "run_formation.sh", f"scenario:={unbounded}", f"window:={window}",
                     f"output_dir:={out}"])
        try:
            self.assertTrue(watcher.wait_for_step(300, 30.0), "the run did not start")
            # This test's own subscriptions must have heard the monitor and every agent before
            # the monitor stops: a stopped node cannot answer a new subscriber's connection.
            end = time.time() + 60
            while (allowed[0] == 0 or len(steps) < self.scenario["n"]) and time.time() < end:
                time.sleep(0.05)
            self.assertGreater(allowed[0], 0, "no progress heard from the monitor in 60 s")
            self.assertEqual(len(steps), self.scenario["n"], f"states heard from agents {sorted(steps)} only")
            monitor = vf_rostest.node_pid("/formation/monitor")
            os.kill(monitor, signal.SIGSTOP)
            time.sleep(1.5)
            held = dict(steps)
            time.sleep(1.0)
            self.assertEqual({i: s for i, (s, _) in steps.items()}, {i: s for i, (s, _) in held.items()},
                             "agents moved while the monitor was stopped")
            stopped_at = watcher.step
            self.assertLessEqual(max(s for s, _ in steps.values()), allowed[0])
            self.assertLessEqual(allowed[0], stopped_at + window)
            os.kill(monitor, signal.SIGCONT)
            self.assertTrue(watcher.wait_for_step(stopped_at + 500, 30.0), "the run did not go on after SIGCONT")
        finally:
            for s in subs:
                s.unregister()
            watcher.unregister()
            os.killpg(run.pid, signal.SIGINT)
            log, _ = run.communicate(timeout=40)
        self.assertEqual(run.returncode, 0, log[-3000:])  # an unbounded run stopped by the user
        with open(os.path.join(out, "unbounded.result.yaml")) as f:
            self.assertEqual(yaml.safe_load(f)["result"], "stopped")

    def test_diverging_run_ends_naming_the_agent_and_the_step(self):
        diverging = self.scenario_variant("diverging", time_step=0.2, kappa=0.0)
        first_nonfinite = {}
        with tempfile.TemporaryDirectory() as tmp:
            traj = os.path.join(tmp, "traj.csv")
            subprocess.run(["rosrun", PKG, "simulate", "--scenario", diverging, "--out", traj], capture_output=True)
            with open(traj) as f:
                for row in list(csv.DictReader(f)):
                    i, k = int(row["agent"]), int(row["step"])
                    if not all(np.isfinite(float(row[c])) for c in "xy"):
                        first_nonfinite[i] = min(first_nonfinite.get(i, k), k)
        self.assertTrue(first_nonfinite, "the variant does not diverge in simulate")
        started = time.time()
        run = run_formation(f"scenario:={diverging}", f"output_dir:={self.tmp}/diverging", timeout=60)
        elapsed = time.time() - started
        out = run.stdout + run.stderr
        self.assertNotEqual(run.returncode, 0, out[-3000:])
        failed = [line for line in out.splitlines() if "monitor: run failed at step" in line]
        self.assertEqual(len(failed), 1, out[-3000:])
        named = re.search(r"/formation/agent_(\d+): step (\d+) is not finite", failed[0])
        self.assertIsNotNone(named, failed[0])
        agent, step = int(named.group(1)), int(named.group(2))
        self.assertEqual(step, first_nonfinite[agent], failed[0])
        self.assertLess(elapsed, 20.0)

    def test_recording_splits_and_stops_at_its_size_limit(self):
        unbounded = self.scenario_variant("unbounded_recorded", steps=0)
        out = os.path.join(self.tmp, "limited")
        watcher = vf_rostest.StepWatcher(queue_size=1000, poll=0.02)
        run = start(["rosrun", PKG, "run_formation.sh", f"scenario:={unbounded}", "record:=true",
                     "record_max_size:=2", "record_split_size:=0.5", f"output_dir:={out}"])
        parts = lambda: sorted(f for f in os.listdir(out) if f.endswith(".bag") or f.endswith(".bag.active"))  # noqa: E731
        try:
            end = time.time() + 60
            while time.time() < end and not (os.path.isdir(out) and len(parts()) >= 4 and watcher.step > 3000):
                time.sleep(0.2)
            sizes = {f: os.path.getsize(os.path.join(out, f)) for f in parts()}
            step_then = watcher.step
            time.sleep(1.0)
            self.assertEqual(sizes, {f: os.path.getsize(os.path.join(out, f)) for f in parts()},
                             "the recording went on past its limit")
            self.assertGreater(watcher.step, step_then, "the run stopped with the recording")
        finally:
            watcher.unregister()
            os.killpg(run.pid, signal.SIGINT)
            log, _ = run.communicate(timeout=40)
        self.assertEqual(run.returncode, 0, log[-3000:])
        self.assertEqual(list(sizes), ["unbounded_recorded.bag"] + [f"unbounded_recorded_{k}.bag" for k in (1, 2, 3)])
        # A file ends with the message that crossed its size, then rosbag adds its index (a few %).
        for f, size in sizes.items():
            self.assertLess(size, 0.5e6 * 1.15, f)
        self.assertLess(sum(sizes.values()), 2e6 * 1.1)
        self.assertGreaterEqual(sum(sizes.values()), 2e6)
        self.assertEqual(log.count("the size limit of 2 MB ends the recording"), 1, log[-3000:])
        # The parts hold the first steps of every agent, without a gap between files.
        steps = {i: set() for i in range(self.scenario["n"])}
        for f in sizes:
            rec = vf_rostest.Recording(os.path.join(out, f))
            for (i, k) in rec.states:
                steps[i].add(k)
        for i, held in steps.items():
            self.assertEqual(sorted(held), list(range(len(held))), f"agent {i}")
            self.assertGreater(len(held), 10)

    def test_bad_node_parameters_are_one_fatal_line(self):
        cases = (("monitor", ["_trail_length:=abc"], "~trail_length: expected an integer"),
                 ("monitor", ["_trail_length:=1"], "~trail_length: must be >= 2"),
                 ("monitor", ["_window:=0"], "~window: must be >= 1"),
                 ("monitor", ["_marker_every:=-1"], "~marker_every: must be >= 0"),
                 ("recorder", ["_bag:=/tmp/vf_probe.bag", "_marker_every:=-2"], "~marker_every: must be >= 0"),
                 ("recorder", ["_bag:=/tmp/vf_probe.bag", "_max_size:=-1"], "~max_size: must be in [0, 1e9) MB"),
                 ("recorder", ["_bag:=/tmp/vf_probe.bag", "_compression:=zip"], "~compression: must be lz4 or none, got 'zip'"),
                 ("agent", ["_id:=1", "_real_time_factor:=inf"], "~real_time_factor"),
                 ("agent", ["_id:=1", "_real_time_factor:=fast"], "~real_time_factor: expected a number"),
                 ("agent", ["_id:=99"], "id: must be an agent id 0..5, got 99"),
                 ("agent", [], "~id: required parameter missing"),
                 ("agent_manager", [], "~agents: required parameter missing"),
                 ("agent_manager", ["_agents:=0 x"], "~agents: 'x' is not an agent id"),
                 ("agent_manager", ["_agents:=2 1 2"], "~agents: agent 2 is listed twice"),
                 ("agent_manager", ["_agents:=1 99"], "id: must be an agent id 0..5, got 99"),
                 ("agent_manager", ["_agents:=1", "_stagger:=-1"], "~stagger: must be >= 0"),
                 ("agent_manager", ["_agents:=4", "_real_time_factor:=fast"], "~real_time_factor: expected a number"))
        for k, (node, params, words) in enumerate(cases):
            # A fresh node name each time: private parameters stay on the master after a run.
            run = subprocess.run(["rosrun", PKG, node, f"__name:=param_probe_{k}", f"_scenario:={self.path}",
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
            # The bag's time is the simulated time: replayed with --clock, rviz runs on it.
            rospy.set_param("/use_sim_time", True)
            procs.append(subprocess.Popen(["rviz", "-d", os.path.join(rospkg_path(), "config", "formation.rviz")],
                                          env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
            time.sleep(8)
            procs.append(subprocess.Popen(["rosbag", "play", "--clock", "-q", "-r", "0.5", self.bag],
                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
            time.sleep(6)
            dump = os.path.join(self.tmp, "shot.xwd")
            with open(dump, "wb") as f:
                subprocess.run(["xwd", "-root", "-silent", "-display", display], stdout=f, check=True)
            png = os.path.join(self.tmp, "rviz.png")
            subprocess.run(["rosrun", PKG, "xwd_to_png.py", dump, png], check=True)
            keep = os.environ.get("VF_SCREENSHOT")
            if keep:
                shutil.copy(png, keep)
        finally:
            rospy.delete_param("/use_sim_time")
            for p in reversed(procs):
                p.terminate()
                try:
                    p.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    p.kill()
        image = matplotlib.image.imread(png)[:, :, :3]
        for rgb, count in zip(vf_rostest.PALETTE, vf_rostest.agent_colour_pixels(image)):
            self.assertGreater(count, 30, f"an agent's colour {rgb} is not in the screenshot")


def rospkg_path():
    import rospkg
    return rospkg.RosPack().get_path(PKG)


if __name__ == "__main__":
    rostest.rosrun(PKG, "launch_test", LaunchTest, sys.argv)
