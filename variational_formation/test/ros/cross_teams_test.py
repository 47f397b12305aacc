#!/usr/bin/python3
"""rostest (cross_teams.test): two formations with `safety:` sent across each other keep apart.

Team a (test/ros/cross_team_a.yaml) heads east and team b (cross_team_b.yaml) west, each paced at
real time, with a row of each in the other's path. The test hears every agent's states itself
and, at each state, measures the distance to the other team's agents as last heard:

- every cross-team pair stays at least 0.9 r apart (the issue's bound; without `avoid` they
  pass through each other);
- each result file reports closest_foreign_approach (an agent of its own team and the other's
  full name, at least 0.9 r) and foreign_constraint_steps > 0, and the statuses carry the closest
  foreign pair with both names;
- each monitor says once that the filter bound on an agent of another formation;
- lockstep: every state before the first step whose filter bound on the other team's agent
  (foreign_constraints_active) equals simulate's bit for bit, and the run departs from simulate
  after it; timed mode (mode:=timed, r widened by age x max_speed): the agents' states say their
  filter bound on the other team;
- a bad `avoid` is one FATAL line naming the parameter and the value, and exit status 2.
"""
import math
import os
import shutil
import subprocess
import sys
import threading
import unittest

import rospy
import rostest
from rosgraph_msgs.msg import Log
from variational_formation_msgs.msg import AgentState, FormationStatus

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402

PKG = vf_rostest.PKG
TEAMS = ("team_a", "team_b")
BOUND_LINE = "bound on an agent of another formation"


@vf_rostest.reported_setup
class CrossTeams(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("cross_teams_test")
        cls.out = rospy.get_param("~output_dir")
        cls.mode = rospy.get_param("~mode", "lockstep")
        here = os.path.dirname(os.path.abspath(__file__))
        cls.scenario = {t: vf_rostest.load_scenario(os.path.join(here, f"cross_team_{t[-1]}.yaml")) for t in TEAMS}
        cls.r = cls.scenario["team_a"]["safety"]["radius"]
        cls.lock = threading.Lock()
        cls.newest = {t: {} for t in TEAMS}  # agent id -> position, as last heard
        cls.closest = (math.inf, None)
        cls.states = 0
        cls.heard = {t: {} for t in TEAMS}  # (agent, step) -> position
        cls.first_bound = {t: math.inf for t in TEAMS}  # first step with foreign_constraints_active > 0
        cls.status = {t: [] for t in TEAMS}
        cls.bound_lines = {t: [] for t in TEAMS}
        subs = [rospy.Subscriber(f"/{t}/formation/agent_{i}/state", AgentState, cls.on_state, t, queue_size=1000)
                for t in TEAMS for i in range(cls.scenario[t]["n"])]
        subs += [rospy.Subscriber(f"/{t}/formation/status", FormationStatus, cls.status[t].append, queue_size=1000)
                 for t in TEAMS]
        subs.append(rospy.Subscriber("/rosout", Log, cls.on_log, queue_size=1000))  # from each node itself
        cls.results = {t: vf_rostest.wait_for_result(os.path.join(cls.out, f"{t}_cross_{t}.result.yaml"), 120.0)
                       for t in TEAMS}
        for s in subs:
            s.unregister()
        print(f"closest cross-team pair {cls.closest[0]:.4f} m ({cls.closest[1]}), r = {cls.r} m, "
              f"over {cls.states} states; results {cls.results}", flush=True)

    @classmethod
    def on_state(cls, msg, team):
        other = TEAMS[1 - TEAMS.index(team)]
        with cls.lock:
            cls.states += 1
            cls.newest[team][msg.id] = list(msg.position)
            cls.heard[team][(msg.id, msg.step)] = list(msg.position)
            if msg.foreign_constraints_active > 0:
                cls.first_bound[team] = min(cls.first_bound[team], msg.step)
            for j, q in cls.newest[other].items():
                d = math.dist(msg.position, q)
                if d < cls.closest[0]:
                    cls.closest = (d, f"{team}/agent_{msg.id} and {other}/agent_{j}")

    @classmethod
    def on_log(cls, msg):
        for t in TEAMS:
            if msg.name == f"/{t}/formation/monitor" and BOUND_LINE in msg.msg:
                cls.bound_lines[t].append(msg.msg)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.out, ignore_errors=True)

    def test_every_cross_team_pair_keeps_apart(self):
        for t in TEAMS:
            self.assertIn(self.results[t].get("result"), ("succeeded", "failed"), f"{t}: no result {self.results[t]}")
            self.assertGreaterEqual(int(self.results[t]["completed_step"]), 900, f"{t}: {self.results[t]}")
        self.assertGreater(self.states, 1000)
        self.assertGreaterEqual(self.closest[0], 0.9 * self.r, self.closest[1])
        self.assertLess(self.closest[0], 1.5 * self.r, "the teams never met: the test proves nothing")

    def test_results_report_the_closest_foreign_pair_and_the_bound_steps(self):
        for t in TEAMS:
            other = TEAMS[1 - TEAMS.index(t)]
            closest = self.results[t].get("closest_foreign_approach")
            self.assertIsInstance(closest, dict, f"{t}: {self.results[t]}")
            self.assertGreaterEqual(closest["distance"], 0.9 * self.r, t)
            own, foreign = closest["agents"]
            self.assertRegex(own, r"^agent_[0-3]$")
            self.assertRegex(foreign, rf"^/{other}/formation/agent_[0-3]$")
            self.assertGreater(int(self.results[t]["foreign_constraint_steps"]), 0, f"{t}: {self.results[t]}")

    def test_statuses_carry_the_closest_foreign_pair(self):
        for t in TEAMS:
            heard = [s for s in self.status[t] if math.isfinite(s.closest_foreign_approach)]
            self.assertTrue(heard, f"{t}: no status with a foreign pair")
            self.assertTrue(all(len(s.closest_foreign_agents) == 2 for s in heard), t)
            self.assertGreaterEqual(min(s.closest_foreign_approach for s in heard), 0.9 * self.r, t)
            self.assertAlmostEqual(min(s.closest_foreign_approach for s in heard),
                                   self.results[t]["closest_foreign_approach"]["distance"], delta=1e-9)

    def test_lockstep_equals_simulate_until_a_foreign_agent_binds(self):
        for t in TEAMS:
            self.assertTrue(math.isfinite(self.first_bound[t]), f"{t}: no state says its filter bound on the other team")
            if self.mode != "lockstep":
                continue
            expected = vf_rostest.simulate(vf_rostest.scenario_path(
                os.path.join(os.path.dirname(os.path.abspath(__file__)), f"cross_team_{t[-1]}.yaml")))
            before = [k for k in self.heard[t] if k[1] < self.first_bound[t]]
            self.assertGreater(len(before), 4 * 300, f"{t}: {len(before)} states before step {self.first_bound[t]}")
            wrong = [k for k in before if self.heard[t][k] != expected[k]]
            self.assertEqual(wrong, [], f"{t}: states before step {self.first_bound[t]} that differ from simulate")
            after = [k for k in self.heard[t] if k[1] > self.first_bound[t] and self.heard[t][k] != expected[k]]
            self.assertTrue(after, f"{t}: the filter bound on the other team, yet the run still equals simulate")
            print(f"{t}: {len(before)} states equal simulate before step {self.first_bound[t]}; "
                  f"{len(after)} differ after it", flush=True)

    def test_each_monitor_says_once_that_the_run_no_longer_equals_simulate(self):
        for t in TEAMS:
            self.assertEqual(len(self.bound_lines[t]), 1, f"{t}: {self.bound_lines[t]}")
            self.assertIn("no longer equals simulate", self.bound_lines[t][0])

    def test_a_bad_avoid_is_one_fatal_line(self):
        here = os.path.dirname(os.path.abspath(__file__))
        run = subprocess.run(["rosrun", PKG, "agent", "__ns:=/bad_avoid/formation", "__name:=agent_0", "_id:=0",
                              f"_scenario:={here}/cross_team_a.yaml", "_avoid:=all team_b"],
                             capture_output=True, text=True, timeout=60)
        self.assertEqual(run.returncode, 2, run.stdout + run.stderr)
        fatal = [line for line in (run.stdout + run.stderr).splitlines() if "FATAL" in line]
        self.assertEqual(len(fatal), 1, run.stdout + run.stderr)
        self.assertIn("/bad_avoid/formation/agent_0/avoid: 'all' in 'all team_b' is not a namespace", fatal[0])


if __name__ == "__main__":
    rostest.rosrun(PKG, "cross_teams_test", CrossTeams, sys.argv)
