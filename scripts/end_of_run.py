#!/usr/bin/python3
"""Ends a launch when the run is over: formation.launch starts it as a required node, and it
exits 0 when the monitor says the run finished and 1 when it failed (the monitor's final
`progress`). The monitor may then respawn after a crash without ending the launch. It also exits
1 on a FATAL line from a node of the formation (a bad configuration at start-up, which a
respawning node would otherwise repeat forever)."""
import sys

import rospy
from rosgraph_msgs.msg import Log
from variational_formation.msg import RunProgress


def main():
    if any(a in ("-h", "--help") for a in sys.argv[1:]):
        print("usage: rosrun variational_formation end_of_run.py [_monitor:=NAME]\n" + __doc__)
        return
    rospy.init_node("end_of_run")
    monitor = rospy.resolve_name(rospy.get_param("~monitor", "monitor"))
    namespace = rospy.get_namespace()
    outcome = []

    def end(status, why):
        if not outcome:
            outcome.append(status)
            rospy.signal_shutdown(why)

    def on_progress(msg):
        if msg._connection_header.get("callerid") == monitor and msg.state in (RunProgress.FINISHED,
                                                                               RunProgress.FAILED):
            end(0 if msg.state == RunProgress.FINISHED else 1, "the run is over")

    def on_log(msg):
        if msg.level == Log.FATAL and msg.name.startswith(namespace):
            end(1, f"{msg.name} failed at start-up")

    rospy.Subscriber("progress", RunProgress, on_progress)
    rospy.Subscriber("/rosout", Log, on_log, queue_size=100)
    rospy.spin()
    sys.exit(outcome[0] if outcome else 0)


if __name__ == "__main__":
    main()
