#!/usr/bin/python3
"""Publishes malformed states on agent_1's state topic during a run (header.frame_id "injected"):
an impossible step, non-finite values, the wrong dimension, an unknown sender. The agents and the
monitor must drop them all; the run must still equal `simulate` bit for bit."""
import math

import rospy
from variational_formation.msg import AgentState


def main():
    rospy.init_node("inject_malformed")
    pub = rospy.Publisher("/formation/agent_1/state", AgentState, queue_size=100)
    rospy.sleep(rospy.get_param("~delay", 1.0))
    cases = [
        dict(id=1, step=10 ** 6, position=[0.0, 0.0], previous_position=[0.0, 0.0]),
        dict(id=1, step=1, position=[math.nan, 0.0], previous_position=[0.0, 0.0]),
        dict(id=1, step=1, position=[0.0, math.inf], previous_position=[0.0, 0.0]),
        dict(id=1, step=1, position=[0.0, 0.0, 0.0], previous_position=[0.0, 0.0, 0.0]),
        dict(id=7, step=1, position=[0.0, 0.0], previous_position=[0.0, 0.0]),
        dict(id=1, step=-5, position=[0.0, 0.0], previous_position=[0.0, 0.0]),
    ]
    rate = rospy.Rate(20)
    for k in range(60):
        if rospy.is_shutdown():
            break
        msg = AgentState(**cases[k % len(cases)])
        msg.header.frame_id = "injected"
        pub.publish(msg)
        rate.sleep()
    rospy.spin()


if __name__ == "__main__":
    main()
