#!/usr/bin/python3
"""A stand-in for an agent whose step 0 is not finite (diverging_safety_test.py): started as that
agent's node (`__name:=agent_0 __ns:=/formation`), it publishes AgentState id 0, step 0 with a NaN
position on the agent's own topic until shut down, as an agent that did not undo a diverged step
would. The monitor must end the run as diverged, not drop the state and wait."""
import math
import time

import rospy
from variational_formation_msgs.msg import AgentState


def main():
    rospy.init_node("agent_0")
    name = rospy.get_name()  # /formation/agent_0
    agent = int(name.rsplit("_", 1)[1])
    pub = rospy.Publisher(name + "/state", AgentState, queue_size=10, latch=True)
    msg = AgentState(id=agent, step=0, position=[math.nan, 0.0], previous_position=[math.nan, 0.0])
    while not rospy.is_shutdown():
        pub.publish(msg)
        time.sleep(0.2)


if __name__ == "__main__":
    main()
