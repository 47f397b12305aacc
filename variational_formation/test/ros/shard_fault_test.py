#!/usr/bin/python3
"""rostest (shard_fault.test): SIGKILL to one of two agent_managers of a formation, ~kills times
in one unpaced, recorded run, each kill once the run has recovered from the last (the monitor
completed a step more than a window past the one it had at the kill, which needs the victim's
new process). The victim's respawned process reloads its agents, which recover from their
holders; where a kill took steps that existed nowhere else, they compute them again from their
neighbours' states in the other manager ("to compute the lost steps again" on /rosout, counted
and printed). The run must end by itself as succeeded, with every (agent, step) state recorded
once and equal to simulate bit for bit (fault_test.FaultRun's checks).

It watches the monitor's status only: subscribing to an agent's own topic would make that agent
publish on it, which the agents of a manager otherwise leave to the manager's batch.
"""
import os
import random
import signal
import sys
import threading
import time

import rospy
import rostest
from rosgraph_msgs.msg import Log
from variational_formation_msgs.msg import FormationStatus

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402
from fault_test import NS, WINDOW, FaultRun  # noqa: E402

VICTIM = f"{NS}/manager_a"
RECOMPUTED = "to compute the lost steps again"


class StatusWatch:
    """The newest completed step (the monitor's status), and the agents' log lines that say they
    compute lost steps again."""

    def __init__(self):
        self.lock = threading.Lock()
        self.step = -1
        self.recomputed = []
        self.subs = [rospy.Subscriber(f"{NS}/status", FormationStatus, self.on_status, queue_size=10000),
                     rospy.Subscriber("/rosout_agg", Log, self.on_log, queue_size=10000)]

    def on_status(self, msg):
        with self.lock:
            self.step = max(self.step, msg.step)

    def on_log(self, msg):
        if RECOMPUTED in msg.msg:
            with self.lock:
                self.recomputed.append(msg.msg)

    def wait_for_step(self, step, timeout=60.0):
        end = time.time() + timeout
        while self.step < step and time.time() < end:
            time.sleep(0.002)
        return self.step >= step


@vf_rostest.reported_setup
class ShardFault(FaultRun):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("shard_fault_test")
        cls.fault = "kill_manager"
        cls.seed = int(rospy.get_param("~seed", 1))
        kills = int(rospy.get_param("~kills", 4))
        cls.out = rospy.get_param("~output_dir")
        cls.path = rospy.get_param("~scenario")
        cls.scenario = vf_rostest.load_scenario(cls.path)
        cls.name = os.path.basename(cls.path).replace(".yaml", "")
        steps = int(cls.scenario["steps"])
        cls.watch = StatusWatch()
        cls.recoveries, cls.injected = [], []
        # Spread over the run's first two thirds: each kill then still finds the run going.
        at = sorted(random.Random(cls.seed).sample(range(steps // 20, 2 * steps // 3), kills))
        for step in at:
            step = max(step, cls.watch.step + 1)
            assert cls.watch.wait_for_step(step), f"the run never reached step {step} (at {cls.watch.step})"
            pid = vf_rostest.node_pid(VICTIM)
            killed_at = time.monotonic()
            os.kill(pid, signal.SIGKILL)
            completed = cls.watch.step
            rospy.loginfo("shard_fault_test: seed %d: SIGKILL to %s (pid %d) at step %d", cls.seed, VICTIM, pid, completed)
            cls.injected.append((completed, [VICTIM]))
            # The agents ran at most a window ahead of the completed step: past that, the
            # victim's new process has computed steps of its own.
            assert cls.watch.wait_for_step(completed + WINDOW + 2, 90.0), (
                f"the run did not recover after {VICTIM} was killed at step {completed} (it stays at {cls.watch.step})")
            cls.recoveries.append(time.monotonic() - killed_at)
        cls.result = vf_rostest.wait_for_result(os.path.join(cls.out, cls.name + ".result.yaml"), 120.0)
        cls.expected = vf_rostest.simulate(cls.path)
        with cls.watch.lock:
            print(f"shard_fault_test: {len(at)} kills at steps {[k for k, _ in cls.injected]}; lost steps computed "
                  f"again {len(cls.watch.recomputed)} times", flush=True)


if __name__ == "__main__":
    rostest.rosrun(vf_rostest.PKG, "shard_fault_test", ShardFault, sys.argv)
