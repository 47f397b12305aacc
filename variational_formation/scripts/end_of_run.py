#!/usr/bin/python3
"""Ends a launch once every formation in it is over, as Ctrl-C would: no red line on success.

formation.launch starts one per formation. Its run is over when the monitor's final `progress`
says finished or failed (the monitor may respawn meanwhile without ending anything). A launch
may include formation.launch several times (under <group ns>): each end_of_run marks its own
formation over in its parameter ~over, and once every formation of the same launch is marked,
the one with the smallest name sends SIGINT to the roslaunch process that started them. A FATAL
line from a node of the formation (a bad configuration at start-up, which a respawning node would
otherwise repeat forever) ends the launch at once.

The formations of one launch are known before any node starts: each sets ~launch at parse time
to the output of `end_of_run.py --launch-id` (the launching process: host, pid, start time), so
none is missed and a stale parameter of an earlier launch on the same master never counts.
Under rostest (or any launcher other than roslaunch) it ends nothing: the test ends the launch.

usage: end_of_run.py --launch-id        prints the id of the process that runs this command
       rosrun variational_formation end_of_run.py [_monitor:=NAME]   (as a node, in formation.launch)
"""
import os
import signal
import socket
import sys
import time

POLL_SECONDS = 0.2
# formation.launch starts this node first. A FATAL line can come while roslaunch still starts the
# monitor, and a SIGINT then would make roslaunch fail that start (a red RLException): wait for
# the monitor to have started, at most this long.
MONITOR_START_SECONDS = 30.0


def process_id(pid):
    """host:pid:start time (clock ticks since boot), which no later process shares."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            start = f.read().rsplit(")", 1)[1].split()[19]
    except (OSError, IndexError):
        start = "0"
    return f"{socket.gethostname()}:{pid}:{start}"


def started_by_roslaunch(pid):
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            argv = f.read().decode(errors="replace").split("\0")
    except OSError:
        return False
    return any(os.path.basename(a) == "roslaunch" for a in argv[:2])


def main():
    if sys.argv[1:2] == ["--launch-id"]:
        print(process_id(os.getppid()), end="")  # a <param command> keeps a newline
        return
    if any(a in ("-h", "--help") for a in sys.argv[1:]):
        print(__doc__)
        return
    import rosgraph
    import rospy
    from rosgraph_msgs.msg import Log
    from variational_formation_msgs.msg import RunProgress

    rospy.init_node("end_of_run")
    monitor = rospy.resolve_name(rospy.get_param("~monitor", "monitor"))
    namespace = rospy.get_namespace()
    launcher = os.getppid()
    # Set at parse time by this launch (see above); the launching process is its parent too.
    launch = str(rospy.get_param("~launch", "")).strip() or process_id(launcher)
    state = {"over": False, "now": False, "marked": False, "monitor_started": False, "since": 0.0}

    def over(why, at_once=False):
        if not state["over"]:
            state["over"] = True
            rospy.loginfo("end_of_run: %s", why)
        state["now"] = state["now"] or at_once

    def on_progress(msg):
        if msg._connection_header.get("callerid") == monitor and msg.state in (RunProgress.FINISHED,
                                                                               RunProgress.FAILED):
            over("the run is over")

    def on_log(msg):
        state["monitor_started"] = state["monitor_started"] or msg.name == monitor
        if msg.level == Log.FATAL and msg.name.startswith(namespace):
            over(f"{msg.name} failed at start-up", at_once=True)

    master = rosgraph.Master(rospy.get_name())

    def other_node_param(name, default):
        """A parameter of another formation's end_of_run (its ~launch or ~over), by full name."""
        return master.getParam(name) if master.hasParam(name) else default

    def formations():
        """The end_of_run nodes (parameter namespaces) of this launch, this one included."""
        return sorted(name[:-len("/launch")] for name in master.getParamNames()
                      if name.endswith("/launch") and str(other_node_param(name, "")).strip() == launch)

    def monitor_started():
        """Whether roslaunch has started the monitor (it registered or logged), or we waited long enough."""
        if not state["monitor_started"]:
            try:
                master.lookupNode(monitor)
                state["monitor_started"] = True
            except Exception:  # not registered (yet): roslaunch is still starting the formation
                state["since"] = state["since"] or time.time()
                if time.time() - state["since"] < MONITOR_START_SECONDS:
                    rospy.loginfo_throttle(5.0, f"end_of_run: waiting for {monitor} to start before ending the launch")
                    return False
                state["monitor_started"] = True
        return True

    rospy.Subscriber("progress", RunProgress, on_progress)
    rospy.Subscriber("/rosout", Log, on_log, queue_size=100)
    while not rospy.is_shutdown():
        time.sleep(POLL_SECONDS)
        if not state["over"]:
            continue
        try:
            if not state["marked"]:
                rospy.set_param("~over", launch)
                state["marked"] = True
            others = formations()
            everyone = state["now"] or all(other_node_param(f + "/over", None) == launch for f in others)
        except Exception as e:  # the master may be busy, or going away with the launch: ask again
            rospy.logwarn_throttle(5.0, f"end_of_run: cannot ask the master which formations are over ({e})")
            continue
        # One sender: a second SIGINT would cut roslaunch's own shutdown short.
        if everyone and not monitor_started():
            continue
        if everyone and (state["now"] or not others or others[0] == rospy.get_name()):
            if started_by_roslaunch(launcher):
                rospy.loginfo("end_of_run: every formation of this launch is over; ending it")
                os.kill(launcher, signal.SIGINT)
            break
    rospy.spin()


if __name__ == "__main__":
    main()
