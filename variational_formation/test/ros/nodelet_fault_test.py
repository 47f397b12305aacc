#!/usr/bin/python3
"""rostest (nodelet_fault.test): SIGKILL to the nodelet manager that hosts every agent, during a
recorded run (formation.launch nodelet:=true). All agents die at once; the manager respawns and
loads every agent again, and every agent recovers from the monitor. The run must end by itself as succeeded, with every (agent, step)
state recorded once and equal to simulate bit for bit, as for fault.test.
Prints the recovery time: from the kill until the monitor completes a step it had not before.
"""
import os
import random
import signal
import sys
import time

import rospy
import rostest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402
from fault_test import NS, FaultRun, Watch  # noqa: E402


@vf_rostest.reported_setup
class ManagerFault(FaultRun):
    @classmethod
    def setUpClass(cls):
        steps = cls.open_run("fault_test", "kill_manager")
        cls.watch = Watch(cls.scenario["n"])
        step = random.Random(cls.seed).randrange(steps // 10, steps - 40)
        assert cls.watch.wait_for_step(step), f"the run never reached step {step}"
        pid = vf_rostest.node_pid(f"{NS}/manager")
        killed_at = time.monotonic()
        os.kill(pid, signal.SIGKILL)
        completed = cls.watch.step
        rospy.loginfo("fault_test: seed %d: SIGKILL to %s/manager (pid %d) at step %d", cls.seed, NS, pid, completed)
        cls.injected.append((completed, [f"{NS}/manager"]))
        while cls.watch.step <= completed + 1 and time.monotonic() - killed_at < 90.0:
            time.sleep(0.002)
        assert cls.watch.step > completed + 1, "no step completed after the manager was killed"
        cls.recoveries.append(time.monotonic() - killed_at)
        cls.result = vf_rostest.wait_for_result(os.path.join(cls.out, cls.name + ".result.yaml"), 120.0)
        cls.expected = vf_rostest.simulate(cls.path)


if __name__ == "__main__":
    rostest.rosrun(vf_rostest.PKG, "nodelet_fault_test", ManagerFault, sys.argv)
