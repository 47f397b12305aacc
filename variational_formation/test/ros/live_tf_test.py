#!/usr/bin/python3
"""rostest (live_tf.test): during a default lockstep run the monitor publishes /clock (the
simulated time of each completed step) and formation.launch sets /use_sim_time, so a tf consumer
needs no setup: tf2 lookups of world -> formation/agent_0 at now() succeed, and each gives agent_0's
own published position at that time's step, exactly."""
import time
import unittest

import rospy
import rostest
import tf2_ros
import yaml
from variational_formation_msgs.msg import AgentState

OWNER = "/formation/agent_0"
LOOKUPS = 20


class LiveTf(unittest.TestCase):
    def test_lookups_at_now_give_the_agents_state_at_that_step(self):
        rospy.init_node("live_tf_test")
        self.assertTrue(rospy.get_param("/use_sim_time", False), "formation.launch did not set /use_sim_time")
        with open(rospy.get_param("~scenario")) as f:
            h = float(yaml.safe_load(f)["time_step"])
        states = {}

        def on_state(msg):
            if msg._connection_header.get("callerid") == OWNER:
                states[msg.step] = list(msg.position)

        rospy.Subscriber(OWNER + "/state", AgentState, on_state, queue_size=100000)
        buffer = tf2_ros.Buffer(cache_time=rospy.Duration(3600.0))
        tf2_ros.TransformListener(buffer)
        end = time.time() + 60.0  # wall time: the test's own limits must not follow the run's clock
        while rospy.Time.now().is_zero() and time.time() < end:
            time.sleep(0.05)
        self.assertFalse(rospy.Time.now().is_zero(), "no /clock from the monitor within 60 s")
        # A listener holds only what arrived after it connected to the broadcasters, which may be
        # after /clock: a consumer that joins a run looks up times from its first transform on.
        while not buffer.can_transform("world", "formation/agent_0", rospy.Time(0)) and time.time() < end:
            time.sleep(0.05)
        found, failures = [], []
        while len(found) < LOOKUPS and time.time() < end:
            now = rospy.Time.now()
            try:
                found.append((now, buffer.lookup_transform("world", "formation/agent_0", now, rospy.Duration(2.0))))
            except (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException) as e:
                failures.append(f"at {now.to_sec():.3f} s: {e}")
            time.sleep(0.1)
        self.assertEqual(failures, [], f"{len(failures)} of {len(found) + len(failures)} lookups at now() failed")
        self.assertEqual(len(found), LOOKUPS)
        self.assertGreater(found[-1][0], found[0][0], "the clock did not move")
        time.sleep(1.0)  # the states of those steps were published before the steps completed
        for now, t in found:
            step = round(now.to_sec() / h)
            self.assertAlmostEqual(step * h, now.to_sec(), delta=1e-6, msg="the clock is not a step's time")
            self.assertEqual(t.header.stamp, now)
            self.assertIn(step, states, f"agent_0's state of step {step} was not received")
            p = states[step]
            self.assertAlmostEqual(t.transform.translation.x, p[0], delta=1e-12)
            self.assertAlmostEqual(t.transform.translation.y, p[1], delta=1e-12)


if __name__ == "__main__":
    rostest.rosrun("variational_formation", "live_tf", LiveTf)
