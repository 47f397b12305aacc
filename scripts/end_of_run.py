#!/usr/bin/python3
"""Ends a launch when the run is over: formation.launch starts it as a required node, and it
exits (0 when the monitor says the run finished, 1 when it failed) on the monitor's final
`progress`. The monitor itself may then respawn after a crash without ending the launch."""
import sys

import rospy
from variational_formation.msg import RunProgress


def main():
    rospy.init_node("end_of_run")
    monitor = rospy.resolve_name(rospy.get_param("~monitor", "monitor"))
    outcome = []

    def on_progress(msg):
        if msg._connection_header.get("callerid") != monitor:
            return
        if msg.state in (RunProgress.FINISHED, RunProgress.FAILED) and not outcome:
            outcome.append(0 if msg.state == RunProgress.FINISHED else 1)
            rospy.signal_shutdown("the run is over")

    rospy.Subscriber("progress", RunProgress, on_progress)
    rospy.spin()
    sys.exit(outcome[0] if outcome else 0)


if __name__ == "__main__":
    main()
