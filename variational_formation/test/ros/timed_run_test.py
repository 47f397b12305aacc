#!/usr/bin/python3
"""rostest (timed_run.test): formation.launch mode:=timed at rate 1, watched live.

Private parameters:
  scenario    path of the scenario (required)
  expect      converged: the last status is congruent (and the run ends by itself);
              not_converged: no status is ever congruent (beyond the delay margin)
  max_age     the agents' (the kill case restarts the agent after respawn_delay 1.5 s)
  kill        >= 0: SIGKILL that agent's process 1 s into the run; its neighbours must hold
              (q_{k+1} = q_k exactly) while it is dead, it respawns, and the formation converges
  reconfigure_kappa  > 0: 2 s into the run, set every agent's kappa to it (dynamic_reconfigure)
  output_dir  where the monitor writes its result file (removed after)
Every case also checks each agent's /diagnostics (step rate near 1/h). It prints the convergence time: the first tick of the final congruent stretch times h / rate.
"""
import math
import os
import shutil
import signal
import sys
import threading
import time
import unittest
import xmlrpc.client

import rosgraph
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from dynamic_reconfigure.client import Client
from variational_formation_msgs.msg import AgentState, FormationStatus

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402

NS = "/formation"


def node_pid(name, old=None, timeout=20.0):
    """The pid of a node (another than `old`: a respawned one)."""
    master = rosgraph.Master("/timed_run_test")
    end = time.time() + timeout
    while time.time() < end:
        try:
            pid = xmlrpc.client.ServerProxy(master.lookupNode(name)).getPid("/timed_run_test")[2]
            if pid != old:
                return pid
        except Exception:
            pass
        time.sleep(0.05)
    raise AssertionError(f"{name} did not come up")


@vf_rostest.reported_setup
class TimedRun(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("timed_run_test")
        cls.path = rospy.get_param("~scenario")
        cls.expect = rospy.get_param("~expect", "converged")
        cls.victim = int(rospy.get_param("~kill", -1))
        cls.max_age = float(rospy.get_param("~max_age", 0.5))
        cls.kappa = float(rospy.get_param("~reconfigure_kappa", 0.0))
        # "vx_vy": a velocity command 2 s into the run, and a stop 6.5 s later (empty: none).
        cls.command = [float(x) for x in str(rospy.get_param("~command", "")).replace("_", " ").split()]
        cls.diagnostics = {}

        def on_diagnostics(msg):
            with lock:
                for st in msg.status:
                    if st.name.endswith(": timed agent"):
                        cls.diagnostics.setdefault(st.name.split(":")[0].split("/")[-1], []).append(st)
        cls.out = rospy.get_param("~output_dir")
        cls.scenario = vf_rostest.load_scenario(cls.path)
        cls.h = float(cls.scenario["time_step"])
        cls.status, cls.states = [], {}
        lock = threading.Lock()

        def on_status(msg):
            with lock:
                cls.status.append((time.monotonic(), msg))

        def on_state(msg):
            with lock:
                cls.states.setdefault(msg.id, []).append((time.monotonic(), msg))

        cls.subs = [rospy.Subscriber(NS + "/status", FormationStatus, on_status, queue_size=100000),
                    rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics, queue_size=1000)]
        cls.neighbours = cls.scenario["neighbours"].get(cls.victim, [])
        for j in cls.neighbours + ([cls.victim] if cls.victim >= 0 else []):
            cls.subs.append(rospy.Subscriber(f"{NS}/agent_{j}/state", AgentState, on_state, queue_size=100000))
        cls.killed_at = cls.respawned_at = None
        if cls.victim >= 0:
            while not cls.status or cls.status[-1][1].step < 70:  # 1 s into the run
                time.sleep(0.01)
            name = f"{NS}/agent_{cls.victim}"
            pid = node_pid(name)
            os.kill(pid, signal.SIGKILL)
            cls.killed_at = time.monotonic()
            node_pid(name, old=pid)
            cls.respawned_at = time.monotonic()
            print(f"agent_{cls.victim} killed, back {cls.respawned_at - cls.killed_at:.2f} s later", flush=True)
        if cls.kappa > 0:
            while not cls.status or cls.status[-1][1].step < 140:  # 2 s into the run
                time.sleep(0.01)
            for i in range(cls.scenario["n"]):
                Client(f"{NS}/agent_{i}", timeout=5).update_configuration({"kappa": cls.kappa})
            print(f"kappa set to {cls.kappa} at tick {cls.status[-1][1].step}", flush=True)
        if cls.command:
            steering = vf_rostest.Steering(NS, cls.scenario["n"])
            while not cls.status or cls.status[-1][1].step < 140:
                time.sleep(0.01)
            cls.sent_at, cls.from_centroid = time.monotonic(), steering.send(*cls.command)
            while cls.status[-1][1].step < 600:
                time.sleep(0.01)
            cls.stopped_at, cls.to_centroid = time.monotonic(), steering.send(0.0, 0.0)
            time.sleep(2.0)  # the coast after the stop: 1/kappa
            cls.end_centroid = steering.centroid()
            steering.close()
        name = os.path.basename(cls.path).replace(".yaml", "")
        cls.result = vf_rostest.wait_for_result(os.path.join(cls.out, name + ".result.yaml"), 50.0)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.out, ignore_errors=True)

    def test_outcome(self):
        self.assertGreater(len(self.status), 100, "too few status messages")
        last = self.status[-1][1]
        ages = sorted(m.max_data_age for _, m in self.status)
        print(f"status: {len(self.status)} messages, median max_data_age {ages[len(ages) // 2]:.4f} s, "
              f"largest {ages[-1]:.3f} s; last max distance error {last.max_distance_error:.4g} m", flush=True)
        if self.expect == "converged":
            self.assertEqual(self.result.get("result"), "succeeded", f"result file: {self.result}")
            self.assertTrue(last.converged, f"max distance error {last.max_distance_error}")
            self.assertLess(last.max_distance_error, 0.05)
            print(f"congruent from tick {last.converged_step}: {last.converged_step * self.h:.2f} s "
                  f"after the start (rate 1)", flush=True)
            if self.victim >= 0:  # the final congruent stretch began after the kill (at tick 70)
                self.assertGreater(last.converged_step, 70)
            # The data the monitor used is fresh: one tick plus transport, well under max_age.
            self.assertLess(ages[len(ages) // 2], 0.1)
        else:
            congruent = [m.step for _, m in self.status if m.converged]
            self.assertEqual(congruent[:5], [], "congruent beyond the delay margin")
            self.assertTrue(self.result.get("result") == "failed" or last.max_distance_error > 0.1,
                            f"result {self.result}, last max distance error {last.max_distance_error}")

    def test_follows_a_commanded_velocity(self):
        if not self.command:
            self.assertFalse(hasattr(self, "sent_at"))  # nothing was sent: the run is the others'
            return
        # Timed agents apply the newest command at their next tick: the centroid moves at v*
        # (after a transient of 1/kappa at each end, which cancels in the displacement).
        seconds = self.stopped_at - self.sent_at
        moved = [b - a for a, b in zip(self.from_centroid, self.end_centroid)]
        wanted = [v * seconds for v in self.command]
        error = math.dist(moved, wanted)
        print(f"commanded {self.command} m/s for {seconds:.2f} s: the centroid moved {moved}, wanted {wanted} "
              f"({100 * error / math.hypot(*wanted):.1f}% off)", flush=True)
        self.assertLess(error, 0.1 * math.hypot(*wanted))
        # While it moves at v* (ticks 500-599, the command from tick 140, the stop at 600), the
        # monitor measures it relative to the commanded motion: congruent, though every agent
        # moves faster than the 0.1 m/s a standing formation may.
        moving = [m for _, m in self.status if 500 <= m.step < 600]
        self.assertGreater(len(moving), 50, "statuses while moving")
        self.assertEqual([m.step for m in moving if not m.converged][:5], [], "not congruent while moving as commanded")

    def test_diagnostics(self):
        self.assertEqual(sorted(self.diagnostics), [f"agent_{i}" for i in range(self.scenario["n"])])
        expected = 1.0 / self.h  # rate 1
        for who, statuses in self.diagnostics.items():
            rates = [float(kv.value) for st in statuses for kv in st.values if kv.key == "step rate [1/s]"]
            stepping = [r for r in rates if r > 0]
            self.assertTrue(stepping, f"{who}: no step rate")
            median = sorted(stepping)[len(stepping) // 2]
            self.assertLess(abs(median - expected), 0.1 * expected, f"{who}: step rates {stepping}")

    def test_neighbours_hold_while_the_killed_agent_is_dead(self):
        if self.victim < 0:
            self.skipTest("no kill in this case")
        # From max_age plus 0.1 s after the kill until its first state after the
        # respawn, every neighbour's state is a hold: q_{k+1} = q_k exactly.
        back = [t for t, m in self.states.get(self.victim, []) if t > self.respawned_at]
        self.assertTrue(back, "no state from the respawned agent")
        start, end = self.killed_at + self.max_age + 0.1, back[0] - 0.05
        print(f"agent_{self.victim}: first state {back[0] - self.killed_at:.2f} s after the kill", flush=True)
        self.assertGreater(end - start, 0.5, "the agent came back too fast to see a hold")
        for j in self.neighbours:
            during = [m for t, m in self.states.get(j, []) if start <= t <= end]
            self.assertGreater(len(during), 20, f"agent_{j} published nothing while agent_{self.victim} was dead")
            moving = [m.step for m in during if list(m.position) != list(m.previous_position)]
            self.assertEqual(moving, [], f"agent_{j} moved while its neighbour was dead")
        # The monitor reported the dead agent's data as old: about as old as it was dead.
        dead = back[0] - self.killed_at
        old = [m.max_data_age for t, m in self.status if self.killed_at <= t <= back[0] + 0.1]
        self.assertTrue(old and max(old) > dead - 0.2, f"max_data_age while dead ({dead:.2f} s): {max(old) if old else None}")


if __name__ == "__main__":
    rostest.rosrun(vf_rostest.PKG, "timed_run", TimedRun)
