#!/usr/bin/python3
"""rostest (kappa_reconfigure.test): kappa changed during a run with the real command line,
`rosrun dynamic_reconfigure dynparam set`, on the unbounded hexagon (kappa 13, h 0.014 s).

Timed mode:
- An agent's own server: kappa -5 is refused (not clamped to 0): the agent keeps 13, reports 13
  back (`dynparam get`), and logs one WARN naming ~kappa, the value -5, the accepted range and the
  kept value. (Before the fix the cfg's min clamped it to 0 silently.)
- The formation's server (the monitor's, `/formation`): kappa 6 reaches every agent (each one's
  own server reports 6, each logs that it applies it); -5 there is refused with a WARN from the
  monitor, and every agent keeps 6: a later 7 is the only value after 6 that any agent applies.
Lockstep mode: the formation's server refuses any change with a WARN saying why (bit for bit
equal to simulate) and keeps 13; the agents serve no kappa at all.
"""
import os
import re
import subprocess
import sys
import time
import unittest

import rosgraph
import rospy
import rostest
from dynamic_reconfigure.client import Client
from rosgraph_msgs.msg import Log

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402

NS = "/formation"
AGENTS = 6
KAPPA = 13.0  # hexagon_unbounded.yaml


def dynparam(*args):
    start = time.time()
    p = subprocess.run(["rosrun", "dynamic_reconfigure", "dynparam"] + list(args), capture_output=True, text=True,
                       timeout=30)
    print(f"dynparam {' '.join(args)}: status {p.returncode}, {time.time() - start:.1f} s", flush=True)
    return p.returncode, p.stdout + p.stderr


@vf_rostest.reported_setup
class KappaReconfigure(unittest.TestCase):
    """What both modes share: the /rosout lines and the servers. Each mode's test is a subclass, and
    the run takes the one its `~mode` names (the launch passes it as an argument too), so no test
    passes without checking anything."""

    @classmethod
    def setUpClass(cls):
        rospy.init_node("kappa_reconfigure_test")
        cls.mode = rospy.get_param("~mode")
        cls.lines = []  # (node, level, text) from /rosout
        cls.rosout = rospy.Subscriber("/rosout", Log, lambda m: cls.lines.append((m.name, m.level, m.msg)),
                                      queue_size=1000)
        rospy.wait_for_service(f"{NS}/set_parameters", timeout=30)
        if cls.mode == "timed":
            for i in range(AGENTS):
                rospy.wait_for_service(f"{NS}/agent_{i}/set_parameters", timeout=30)
        # /rosout from the monitor and every agent: their WARN lines must reach us.
        end = time.time() + 10
        while cls.rosout.get_num_connections() < AGENTS + 1 and time.time() < end:
            time.sleep(0.05)

    def kappa_of(self, server):
        return Client(server, timeout=10).get_configuration(timeout=10)["kappa"]

    def wait_for_line(self, node, level, *fragments, timeout=10.0):
        end = time.time() + timeout
        while time.time() < end:
            for name, lv, text in list(self.lines):
                if name == node and lv == level and all(f in text for f in fragments):
                    return text
            time.sleep(0.05)
        self.fail(f"no line from {node} with {fragments}; its lines: "
                  f"{[t for n, _, t in self.lines if n == node]}")

    def set(self, server, value):
        status, out = dynparam("set", server, "kappa", value)
        self.assertEqual(status, 0, out)


class KappaTimed(KappaReconfigure):
    def test_timed(self):
        self.assertEqual(self.mode, "timed")
        # An agent's own server: refused, not clamped.
        self.set(f"{NS}/agent_1", "-5")
        line = self.wait_for_line(f"{NS}/agent_1", Log.WARN, "~kappa: -5 refused")
        print(line, flush=True)
        self.assertIn("outside the accepted range [0, ", line)
        self.assertIn("kappa stays 13", line)
        self.assertEqual(self.kappa_of(f"{NS}/agent_1"), KAPPA)  # what `dynparam get` shows

        # The formation's server: one call for every agent.
        self.set(NS, "6")
        self.wait_for_line(f"{NS}/monitor", Log.INFO, f"{NS}/kappa set to 6 for every agent")
        for i in range(AGENTS):
            self.wait_for_line(f"{NS}/agent_{i}", Log.INFO, "kappa set to 6 from step", "the formation's kappa")
            self.assertEqual(self.kappa_of(f"{NS}/agent_{i}"), 6.0, f"agent_{i}")
        self.assertEqual(self.kappa_of(NS), 6.0)

        # Refused at the formation: every agent keeps 6.
        self.set(NS, "-5")
        line = self.wait_for_line(f"{NS}/monitor", Log.WARN, f"{NS}/kappa: -5 refused")
        print(line, flush=True)
        self.assertIn("outside the accepted range [0, ", line)
        self.assertIn("kappa stays 6", line)
        self.assertEqual(self.kappa_of(NS), 6.0)
        for i in range(AGENTS):
            self.assertEqual(self.kappa_of(f"{NS}/agent_{i}"), 6.0, f"agent_{i}")
        # The refused -5 sent nothing: a later 7 takes the same path, and once every agent has
        # applied it, the agent's kappa lines since the 6 are that 7 alone.
        self.set(NS, "7")
        for i in range(AGENTS):
            self.wait_for_line(f"{NS}/agent_{i}", Log.INFO, "kappa set to 7 from step", "the formation's kappa")
            applied = [m.group(1) for n, _, t in list(self.lines) if n == f"{NS}/agent_{i}"
                       for m in [re.search(r"kappa set to (\S+) from step", t)] if m]
            self.assertEqual(applied, ["6", "7"], f"agent_{i}: the kappa values it applied")


class KappaLockstep(KappaReconfigure):
    def test_lockstep(self):
        self.assertEqual(self.mode, "lockstep")
        self.set(NS, "6")
        line = self.wait_for_line(f"{NS}/monitor", Log.WARN, f"{NS}/kappa: 6 refused, kappa stays 13",
                                  "bit for bit")
        print(line, flush=True)
        self.assertEqual(self.kappa_of(NS), KAPPA)
        # Lockstep agents serve no kappa of their own.
        services = {name for name, _ in rosgraph.Master("/kappa_reconfigure_test").getSystemState()[2]}
        self.assertNotIn(f"{NS}/agent_0/set_parameters", services)


if __name__ == "__main__":
    MODES = {"timed": KappaTimed, "lockstep": KappaLockstep}
    mode = [a for a in sys.argv[1:] if a in MODES]
    if len(mode) != 1:
        sys.exit(f"kappa_reconfigure_test.py: give the mode as an argument, one of {sorted(MODES)}; got {sys.argv[1:]}")
    rostest.rosrun(vf_rostest.PKG, "kappa_reconfigure", MODES[mode[0]])
