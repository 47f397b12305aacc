#!/usr/bin/python3
"""A foreign node that forges agent_0's states during a run: well-formed ones (id 0, the step
agent_0 will publish next, a wrong position), which a check of contents alone would accept, and
malformed ones (non-finite, wrong dimension, wrong id, impossible steps). Every receiver must drop
all of them, because they do not come from the node that owns agent_0. With ~batch_topic (a
manager's batch, `<ns>/manager/states`) it also forges batches holding the same states there,
which the monitor and the recorder must drop because they do not come from that manager. It
publishes for ~duration seconds once the run moves, then sets ~published (how many states it sent
to subscribers) and ~published_batches."""
import math
import time

import rospy
from variational_formation_msgs.msg import AgentState, AgentStates

OWNER = "/formation/agent_0"


def main():
    rospy.init_node("inject_forged")
    latest = {"step": -1, "d": 2}

    def on_state(msg):
        # From agent_0's node, or from the manager it runs in as a nodelet.
        if msg._connection_header.get("callerid") in (OWNER, "/formation/manager") and msg.id == 0:
            latest["step"], latest["d"] = max(latest["step"], msg.step), len(msg.position)

    rospy.Subscriber(OWNER + "/state", AgentState, on_state)
    pub = rospy.Publisher(OWNER + "/state", AgentState, queue_size=100)
    batch_topic = rospy.get_param("~batch_topic", "")
    batch_pub = rospy.Publisher(batch_topic, AgentStates, queue_size=100) if batch_topic else None
    while not rospy.is_shutdown() and latest["step"] < 1:
        time.sleep(0.01)
    # Wall time: under /use_sim_time the run's clock races ahead, or stops when the run ends.
    published, batches, k = 0, 0, 0
    end = time.time() + rospy.get_param("~duration", 3.0)
    while not rospy.is_shutdown() and time.time() < end:
        d, step = latest["d"], latest["step"] + 1
        cases = [
            dict(id=0, step=step, position=[0.5] * d, previous_position=[0.25] * d),  # well-formed
            dict(id=0, step=step, position=[math.nan] + [0.0] * (d - 1), previous_position=[0.0] * d),
            dict(id=0, step=step, position=[0.0] * (d + 1), previous_position=[0.0] * (d + 1)),
            dict(id=7, step=step, position=[0.0] * d, previous_position=[0.0] * d),
            dict(id=0, step=10 ** 6, position=[0.0] * d, previous_position=[0.0] * d),
        ]
        msg = AgentState(**cases[k % len(cases)])
        msg.header.frame_id = "world"
        if pub.get_num_connections() > 0:
            pub.publish(msg)
            published += 1
        if batch_pub is not None and batch_pub.get_num_connections() > 0:
            batch_pub.publish(AgentStates(states=[msg]))
            batches += 1
        k += 1
        time.sleep(0.02)
    rospy.set_param("~published", published)
    rospy.set_param("~published_batches", batches)
    rospy.loginfo("inject_forged: published %d forged states of agent_0 and %d forged batches", published, batches)
    rospy.spin()


if __name__ == "__main__":
    main()
