#!/usr/bin/python3
"""rostest (shard_fault.test): SIGKILLs to one of two agent_managers of a formation, in one
unpaced, recorded run: ~pairs pairs of kills, the second 0.2 to 0.8 s after the respawned process
registered (while its agents recover or have just resumed). Each pair waits until the run has
recovered, that is until the monitor completed a step more than a window past the one it had at
the last kill, which needs the victim's new process. The respawned process reloads its agents,
which recover from their holders: where a kill took steps that existed nowhere else, they compute
them again from their neighbours' states in the other manager; where the monitor had not yet
connected to the new process, they wait for it. The run must end by itself as succeeded, with
every (agent, step) state recorded once and equal to simulate bit for bit (fault_test.FaultRun's
checks). It prints how often the agents resumed, computed lost steps again and waited (their
lines on /rosout).

It watches the monitor's status only: subscribing to an agent's own topic would make that agent
publish on it, which the agents of a manager otherwise leave to the manager's batch.
"""
import os
import random
import signal
import sys
import time

import rospy
import rostest
from rosgraph_msgs.msg import Log

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402
from fault_test import NS, WINDOW, FaultRun  # noqa: E402

VICTIM = f"{NS}/manager_a"
RECOMPUTED = "to compute the lost steps again"
WAITED = "the agent waited for it"  # a resumed agent that waited for the monitor to connect
RESUMED = "; resuming"  # "agent_i: recovered step k from ...; resuming"


class StatusWatch(vf_rostest.StepWatcher):
    """The newest completed step (the monitor's status), and the agents' log lines that say they
    compute lost steps again or waited for the monitor."""

    def __init__(self):
        super().__init__(f"{NS}/status", poll=0.002)
        self.recomputed, self.waited, self.resumed = [], [], []
        self.subs.append(rospy.Subscriber("/rosout", Log, self.on_log, queue_size=10000))

    def on_log(self, msg):
        if RECOMPUTED in msg.msg:
            with self.lock:
                self.recomputed.append(msg.msg)
        elif WAITED in msg.msg:
            with self.lock:
                self.waited.append(msg.msg)
        elif RESUMED in msg.msg:
            with self.lock:
                self.resumed.append(msg.msg)


@vf_rostest.reported_setup
class ShardFault(FaultRun):
    @classmethod
    def setUpClass(cls):
        steps = cls.open_run("shard_fault_test", "kill_manager", scenario=None)
        pairs = int(rospy.get_param("~pairs", 2))
        cls.watch = StatusWatch()
        rng = random.Random(cls.seed)
        # Spread over the run's first two thirds: each pair then still finds the run going.
        at = sorted(rng.sample(range(steps // 20, 2 * steps // 3), pairs))
        for step in at:
            step = max(step, cls.watch.step + 1)
            assert cls.watch.wait_for_step(step), f"the run never reached step {step} (at {cls.watch.step})"
            first = cls.kill(step)
            # The second kill of a pair: soon after the respawned process registered, while its
            # agents recover or have just resumed.
            pid = vf_rostest.node_pid(VICTIM)
            end = time.monotonic() + 30.0
            while pid == first and time.monotonic() < end:
                time.sleep(0.01)
                pid = vf_rostest.node_pid(VICTIM)
            assert pid != first, f"{VICTIM} was not respawned within 30 s"
            time.sleep(rng.uniform(0.2, 0.8))
            completed = cls.watch.step
            killed_at = time.monotonic()
            cls.kill(completed)
            # The agents ran at most a window ahead of the completed step: past that, the
            # victim's new process has computed steps of its own.
            assert cls.watch.wait_for_step(completed + WINDOW + 2, 90.0), (
                f"the run did not recover after {VICTIM} was killed at step {completed} (it stays at {cls.watch.step})")
            cls.recoveries.append(time.monotonic() - killed_at)
        cls.result = vf_rostest.wait_for_result(os.path.join(cls.out, cls.name + ".result.yaml"), 120.0)
        cls.expected = vf_rostest.simulate(cls.path)
        with cls.watch.lock:
            print(f"shard_fault_test: {len(cls.injected)} kills at steps {[k for k, _ in cls.injected]}; agents resumed "
                  f"{len(cls.watch.resumed)} times; lost steps "
                  f"computed again {len(cls.watch.recomputed)} times; a resumed agent waited for the monitor to connect "
                  f"{len(cls.watch.waited)} times", flush=True)

    @classmethod
    def kill(cls, step):
        """SIGKILL to the victim's process; returns its pid."""
        pid = vf_rostest.node_pid(VICTIM)
        os.kill(pid, signal.SIGKILL)
        rospy.loginfo("shard_fault_test: seed %d: SIGKILL to %s (pid %d) at step %d", cls.seed, VICTIM, pid, step)
        cls.injected.append((step, [VICTIM]))
        return pid

if __name__ == "__main__":
    rostest.rosrun(vf_rostest.PKG, "shard_fault_test", ShardFault, sys.argv)
