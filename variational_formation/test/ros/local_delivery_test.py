#!/usr/bin/python3
"""rostest (local_delivery.test): with local delivery on (agents of an agent_manager hand their
states to each other in the process, doc/distributed.md), a subscriber outside the manager still
gets every state of an agent's topic, and a late one the newest at once, as from the latched topic
before:

- `early`: agent_2's topic, subscribed as the launch starts: every step from its first to the
  last, once each, in order; the first is the newest the agent had published (step 0 if it
  subscribed before the run moved; roscpp may repeat that first one, identical);
- `late`: agent_4's topic (the other manager), subscribed once the status passed step 100: its
  first state is at least the status step seen just before subscribing (the newest, not an old
  one), then every step to the last;
- `after`: agent_0's and agent_5's topics, subscribed after the run ended (nothing is published
  any more): each gets exactly its last state, at once;
- every state received equals `simulate` bit for bit; the run (monitor's result) succeeded.
"""
import os
import shutil
import sys
import threading
import time
import unittest

import rospy
import rostest
from variational_formation_msgs.msg import AgentState, FormationStatus

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402

NS = "/formation"
LATE_AFTER = 100  # the late subscriber subscribes once the status passed this step


class Listener:
    """Every message of one agent's topic, with the wall time it arrived."""

    def __init__(self, agent):
        self.lock, self.states, self.headers = threading.Lock(), [], []
        self.subscribed_at = time.monotonic()
        self.sub = rospy.Subscriber(f"{NS}/agent_{agent}/state", AgentState, self.on_state, queue_size=100000)

    def on_state(self, msg):
        with self.lock:
            self.states.append((time.monotonic(), msg))
            self.headers.append(dict(msg._connection_header))

    def steps(self):
        with self.lock:
            return [m.step for _, m in self.states]


@vf_rostest.reported_setup
class LocalDelivery(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("local_delivery_test")
        cls.early = Listener(2)
        cls.path = rospy.get_param("~scenario")
        cls.out = rospy.get_param("~output_dir")
        cls.scenario = vf_rostest.load_scenario(cls.path)
        cls.steps = int(cls.scenario["steps"])
        cls.expected = vf_rostest.simulate(cls.path)
        status = {"step": -1}
        cls.status_sub = rospy.Subscriber(f"{NS}/status", FormationStatus,
                                          lambda m: status.update(step=max(status["step"], m.step)), queue_size=1000)
        end = time.time() + 60.0
        while status["step"] < LATE_AFTER and time.time() < end:
            time.sleep(0.005)
        cls.seen_before_late = status["step"]
        cls.late = Listener(4)
        name = os.path.basename(cls.path).replace(".yaml", "")
        cls.result = vf_rostest.wait_for_result(os.path.join(cls.out, name + ".result.yaml"), 60.0)
        # The last states reach the listeners (the checks below want every step up to the last).
        last = lambda: all(l.steps() and l.steps()[-1] >= cls.steps for l in (cls.early, cls.late))  # noqa: E731
        assert vf_rostest.wait_until(last, 10.0), \
            f"the listeners' last steps {[l.steps()[-1:] for l in (cls.early, cls.late)]}, not {cls.steps}, 10 s after the result"
        cls.after = {}
        for agent in (0, 5):
            t0 = time.monotonic()
            msg = rospy.wait_for_message(f"{NS}/agent_{agent}/state", AgentState, timeout=10.0)
            cls.after[agent] = (msg, time.monotonic() - t0)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.out, ignore_errors=True)

    def check_every_step_from_first(self, listener, agent):
        steps = listener.steps()
        self.assertTrue(steps, f"agent_{agent}: nothing received")
        # roscpp may send a new subscriber its first state twice: a publish sets the latched
        # message at once and queues the broadcast for the poll thread, which can connect the
        # subscriber in between (it gets the latched copy, then the broadcast). Only that one
        # repeat, identical, is allowed; every other step comes once.
        if len(steps) > 1 and steps[0] == steps[1]:
            with listener.lock:
                first, again = listener.states[0][1], listener.states[1][1]
            self.assertEqual((list(first.position), list(first.previous_position)),
                             (list(again.position), list(again.previous_position)),
                             f"agent_{agent}: the repeated first state (step {steps[0]}) differs")
            steps = steps[1:]
        self.assertEqual(steps, list(range(steps[0], self.steps + 1)),
                         f"agent_{agent}: not every step once, in order, from the first to {self.steps}")
        with listener.lock:
            differ = [m.step for _, m in listener.states if list(m.position) != self.expected[(agent, m.step)]]
            ids = {m.id for _, m in listener.states}
        self.assertEqual(differ[:5], [], f"agent_{agent}: {len(differ)} states differ from simulate")
        self.assertEqual(ids, {agent})
        return steps

    def test_run_succeeded(self):
        self.assertEqual(self.result.get("result"), "succeeded", self.result)

    def test_early_subscriber_gets_every_state(self):
        steps = self.check_every_step_from_first(self.early, 2)
        # It subscribed as the launch started; the late one waited for step 100 first.
        self.assertLess(steps[0], LATE_AFTER, "the early subscriber missed the start of the run")
        # Published by agent_2's manager, latched (live once a subscriber from outside connected:
        # TopicAudience, test_topic_audience).
        self.assertEqual({h["callerid"] for h in self.early.headers}, {NS + "/manager_a"})
        self.assertEqual({h.get("latching") for h in self.early.headers}, {"1"})

    def test_late_subscriber_gets_the_newest_then_every_state(self):
        self.assertGreaterEqual(self.seen_before_late, LATE_AFTER, "the run did not get past step 100")
        steps = self.check_every_step_from_first(self.late, 4)
        # agent_4 had published at least the step the status completed before the subscription.
        self.assertGreaterEqual(steps[0], self.seen_before_late)
        self.assertEqual({h["callerid"] for h in self.late.headers}, {NS + "/manager_b"})

    def test_subscriber_after_the_run_gets_the_last_state_at_once(self):
        for agent, (msg, waited) in self.after.items():
            self.assertEqual((msg.id, msg.step), (agent, self.steps), f"agent_{agent}")
            self.assertEqual(list(msg.position), self.expected[(agent, self.steps)], f"agent_{agent}")
            self.assertLess(waited, 5.0, f"agent_{agent}: the newest state came only after {waited:.1f} s")


if __name__ == "__main__":
    rostest.rosrun(vf_rostest.PKG, "local_delivery_test", LocalDelivery, sys.argv)
