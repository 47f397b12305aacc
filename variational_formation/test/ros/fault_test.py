#!/usr/bin/python3
"""rostest (fault.test): injects a real fault into a recorded run and checks what it leaves.

Faults (~fault), at a step drawn from ~seed (reported in the output):
  kill_agent        SIGKILL to one agent (~kills times, each after the previous one recovered)
  kill_agent_twice  the same agent killed twice in one run
  kill_two          two non-adjacent agents killed at the same moment
  stop_agent        SIGSTOP to an agent for 5 s, then SIGCONT
  kill_monitor      SIGKILL to the monitor: it respawns, rebuilds its steps from the agents'
                    histories and goes on; every step's status is right, Noether included
  kill_recorder     SIGKILL to the recorder: the run fails naming it, and the bag it leaves is
                    readable after `rosbag reindex`, with every step recorded so far intact
  kill_holders_stopped
                    SIGSTOP to an agent's neighbours and the monitor (its recall holders), then
                    SIGKILL to the agent: the respawned one gets no answer, starts from the
                    scenario, and on SIGCONT sees its neighbours far past step 0. It must ask its
                    holders again and resume from them (doc/distributed.md, "Crash recovery")
For agent faults it also prints the recovery time: from the kill until the respawned agent
publishes a step it had not published before.
"""
import os
import random
import shutil
import signal
import statistics
import subprocess
import sys
import time
import unittest

import math
import rosbag
import rospy
import rostest
from variational_formation_msgs.msg import AgentState
from variational_formation_msgs.srv import RecallHistory

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402

NS = "/formation"
# formation.launch's default window: agents run up to this many steps ahead of the last step the
# watch has seen complete, so a killed agent has new steps to publish only if it is killed at
# least this far from the end.
WINDOW = 100




class Watch(vf_rostest.StepWatcher):
    """Live view of the run: the newest completed step, and each agent's newest step with the
    time it arrived."""

    def __init__(self, n):
        super().__init__(f"{NS}/status")
        self.newest = {i: (-1, 0.0) for i in range(n)}
        self.last = {i: -1 for i in range(n)}  # the step of each agent's last state, older or not
        self.subs += [rospy.Subscriber(f"{NS}/agent_{i}/state", AgentState, self.on_state, i, queue_size=10000)
                      for i in range(n)]

    def on_state(self, msg, i):
        if msg._connection_header.get("callerid") != f"{NS}/agent_{i}":
            return
        with self.lock:
            self.last[i] = msg.step
            if msg.step > self.newest[i][0]:
                self.newest[i] = (msg.step, time.monotonic())

    def wait_for_agent_beyond(self, agent, step, timeout=60.0):
        """Seconds until agent publishes a step > `step` (None on timeout)."""
        start = time.monotonic()
        while time.monotonic() - start < timeout:
            with self.lock:
                newest, at = self.newest[agent]
            if newest > step:
                return at - start
            time.sleep(0.002)
        return None


@vf_rostest.reported_setup
class FaultRun(unittest.TestCase, vf_rostest.RunChecks):
    @classmethod
    def open_run(cls, node, fault=None, scenario="hexagon"):
        """What every fault run's set-up begins with: this test's node, its fault (~fault if None),
        ~seed, ~output_dir and the scenario (~scenario: a file, or a name under config/, whose
        default is `scenario`; None: it must be given), and no fault injected yet. Returns the
        scenario's step count."""
        rospy.init_node(node)
        cls.fault = rospy.get_param("~fault") if fault is None else fault
        cls.seed = int(rospy.get_param("~seed", 1))
        cls.out = rospy.get_param("~output_dir")
        name = rospy.get_param("~scenario") if scenario is None else rospy.get_param("~scenario", scenario)
        cls.path = vf_rostest.scenario_path(name)
        cls.scenario = vf_rostest.load_scenario(cls.path)
        cls.name = os.path.basename(cls.path).replace(".yaml", "")
        cls.recoveries, cls.injected = [], []
        return int(cls.scenario["steps"])

    @classmethod
    def setUpClass(cls):
        steps = cls.open_run("fault_test")
        cls.kills = int(rospy.get_param("~kills", 1))
        n = cls.scenario["n"]
        rng = random.Random(cls.seed)
        cls.watch = Watch(n)
        if cls.fault in ("kill_agent", "kill_agent_twice", "stop_agent"):
            victim = rng.randrange(n)
            count = 2 if cls.fault == "kill_agent_twice" else cls.kills
            at = sorted(rng.sample(range(20, steps - WINDOW - 40), count))
            # Kills one after another: each waits until the previous one has recovered.
            for step in at:
                cls.inject(step, [victim], signal.SIGSTOP if cls.fault == "stop_agent" else signal.SIGKILL)
        elif cls.fault == "kill_two":
            first = rng.choice([i for i in range(n) if len(cls.scenario["neighbours"][i]) < n - 1])
            others = [j for j in range(n) if j != first and j not in cls.scenario["neighbours"][first]]
            cls.inject(rng.randrange(20, steps - WINDOW - 40), [first, rng.choice(others)], signal.SIGKILL)
        elif cls.fault == "kill_monitor":
            cls.inject(rng.randrange(20, steps - 40), ["monitor"], signal.SIGKILL)
        elif cls.fault == "kill_recorder":
            cls.inject(rng.randrange(20, steps - 40), ["recorder"], signal.SIGKILL)
        elif cls.fault == "kill_holders_stopped":
            cls.kill_with_holders_stopped(rng.randrange(20, steps // 2), rng.randrange(n))
        else:
            raise AssertionError(f"unknown ~fault {cls.fault}")
        cls.result = vf_rostest.wait_for_result(os.path.join(cls.out, cls.name + ".result.yaml"), 120.0)
        cls.expected = vf_rostest.simulate(cls.path)

    @classmethod
    def inject(cls, step, victims, sig):
        assert cls.watch.wait_for_step(step), (
            f"the run never reached step {step}: the newest complete step seen is {cls.watch.step}, "
            f"the result file says {vf_rostest.wait_for_result(os.path.join(cls.out, cls.name + '.result.yaml'), 0.0)}")
        names = [f"{NS}/agent_{v}" if isinstance(v, int) else f"{NS}/{v}" for v in victims]
        pids = [vf_rostest.node_pid(name) for name in names]
        before = {v: cls.watch.newest[v][0] for v in victims if isinstance(v, int)}
        for pid in pids:
            os.kill(pid, sig)
        rospy.loginfo("fault_test: seed %d: %s to %s at step %d", cls.seed, signal.Signals(sig).name,
                      ", ".join(names), step)
        cls.injected.append((step, names))
        if sig == signal.SIGSTOP:
            time.sleep(5.0)
            for pid in pids:
                os.kill(pid, signal.SIGCONT)
        for v, last in before.items():
            seconds = cls.watch.wait_for_agent_beyond(v, last)
            assert seconds is not None, (f"agent_{v} never published a step after {last} after the fault at step "
                                         f"{step} (the newest complete step seen is {cls.watch.step})")
            if sig == signal.SIGKILL:
                cls.recoveries.append(seconds)
        if cls.fault == "kill_monitor":
            # The respawned monitor goes on: wait until it completes steps again.
            assert cls.watch.wait_for_step(step + 30), "no status after the monitor was killed"
            cls.monitor_pids = (pids[0], vf_rostest.node_pid(f"{NS}/monitor"))

    @classmethod
    def kill_with_holders_stopped(cls, step, victim):
        assert cls.watch.wait_for_step(step), f"the run never reached step {step}"
        holders = [f"{NS}/agent_{j}" for j in cls.scenario["neighbours"][victim]] + [f"{NS}/monitor"]
        stopped = [vf_rostest.node_pid(h) for h in holders]
        for pid in stopped:
            os.kill(pid, signal.SIGSTOP)
        time.sleep(0.5)  # what the victim still publishes reaches only stopped receivers
        before = cls.watch.newest[victim][0]
        os.kill(vf_rostest.node_pid(f"{NS}/agent_{victim}"), signal.SIGKILL)
        rospy.loginfo("fault_test: seed %d: SIGSTOP to %s, then SIGKILL to agent_%d at its step %d", cls.seed,
                      ", ".join(holders), victim, before)
        cls.injected.append((step, [f"{NS}/agent_{victim}"]))
        # The respawned agent's recall gets no answer within its 2 s: it starts from the scenario.
        # The test may not see its step 0 on the topic: the master tells a topic's subscribers of
        # a new publisher from a few worker threads, which its calls to the stopped holders block.
        # So it also asks the agent's own ~history, a call that needs no such notice.
        history = rospy.ServiceProxy(f"{NS}/agent_{victim}/history", RecallHistory)
        end, started = time.time() + 30, False
        while not started and time.time() < end:
            started = cls.watch.last[victim] == 0
            try:
                started = started or any(s.step == 0 for s in history(victim).states)
            except (rospy.ServiceException, rospy.ROSException, OSError):
                pass  # the new incarnation does not serve yet (the dead one may still be registered)
            time.sleep(0.05)
        for pid in stopped:
            os.kill(pid, signal.SIGCONT)
        assert started, f"the respawned agent_{victim} never published step 0 (its last state: {cls.watch.last[victim]})"
        seconds = cls.watch.wait_for_agent_beyond(victim, before)
        assert seconds is not None, (f"agent_{victim}, started from the scenario, never went past its old step "
                                     f"{before} (the newest complete step seen is {cls.watch.step})")

    @classmethod
    def tearDownClass(cls):
        if cls.recoveries:
            line = (f"fault_test: recovery after SIGKILL: median {statistics.median(cls.recoveries):.3f} s, "
                    f"max {max(cls.recoveries):.3f} s over {len(cls.recoveries)} kills")
            print(line, flush=True)
            stats = rospy.get_param("~stats_file", "")
            if stats:
                with open(stats, "w") as f:
                    f.write(line + "\n")
        shutil.rmtree(cls.out, ignore_errors=True)

    def test_outcome_and_recording(self):
        self.assertTrue(self.injected, "no fault was injected")
        if self.fault == "kill_recorder":
            self.check_what_a_killed_recorder_leaves()
            return
        self.assertEqual(self.result.get("result"), "succeeded", f"result file: {self.result}")
        rec = vf_rostest.Recording(os.path.join(self.out, self.name + ".bag"))
        self.check_recording_once(rec)
        if self.fault == "kill_monitor":
            self.check_status_after_monitor_restart(rec)

    def check_recording_once(self, rec):
        # A repeat that differs from the written copy fails the run (checked above).
        n, steps = self.scenario["n"], int(self.scenario["steps"])
        self.check_each_step_once(rec, n, steps)
        mismatches = sum(list(m.position) != self.expected[key] or list(m.previous_position) != (
            self.expected[(key[0], max(key[1] - 1, 0))]) for key, msgs in rec.states.items() for m in msgs)
        self.assertEqual(mismatches, 0, "recorded states differ from simulate")
        self.check_noether(rec)

    def check_status_after_monitor_restart(self, rec):
        # Congruence computed here from simulate's trajectory (all pairs within 1%, speeds < 0.1),
        # against every recorded status: the restarted monitor carries the stretch on.
        n, h = self.scenario["n"], float(self.scenario["time_step"])
        desired = [a["desired_position"] for a in self.scenario["agents"]]
        since = -1
        for k in range(int(self.scenario["steps"]) + 1):
            q = [self.expected[(i, k)] for i in range(n)]
            qp = [self.expected[(i, max(k - 1, 0))] for i in range(n)]
            slow = all(math.dist(q[i], qp[i]) / h < 0.1 for i in range(n)) if k else False
            pairs = all(abs(math.dist(q[i], q[j]) - math.dist(desired[i], desired[j]))
                        <= 0.01 * math.dist(desired[i], desired[j]) for i in range(n) for j in range(i + 1, n))
            congruent = slow and pairs
            since = (since if since >= 0 else k) if congruent else -1
            for s in rec.status[k]:
                self.assertEqual(s.converged, congruent, f"step {k}")
                self.assertEqual(s.converged_step, since, f"step {k}")
        killed, now = self.monitor_pids
        self.assertNotEqual(killed, now, "the monitor that finished the run is the one that was killed")

    def check_what_a_killed_recorder_leaves(self):
        self.assertEqual(self.result.get("result"), "failed", f"result file: {self.result}")
        self.assertIn("the recorder", self.result.get("reason", ""))
        # The recorder writes the bag in place; killed, it leaves it without its index.
        bag = os.path.join(self.out, self.name + ".bag")
        self.assertTrue(os.path.exists(bag), os.listdir(self.out))
        with self.assertRaises(rosbag.ROSBagUnindexedException):
            rosbag.Bag(bag).close()
        subprocess.run(["rosbag", "reindex", "--quiet", bag], check=True, capture_output=True)
        rec = vf_rostest.Recording(bag)
        killed_at = self.injected[0][0]
        for i in range(self.scenario["n"]):
            held = sorted(k for (j, k) in rec.states if j == i)
            self.assertEqual(held, list(range(len(held))), f"agent {i}: a gap in what was recorded")
            self.assertGreater(len(held), killed_at - 100 - 10, f"agent {i}: steps recorded before the kill lost")
        for key, msgs in rec.states.items():
            for m in msgs:
                self.assertEqual(list(m.position), self.expected[key], key)


if __name__ == "__main__":
    rostest.rosrun(vf_rostest.PKG, "fault_test", FaultRun, sys.argv)
