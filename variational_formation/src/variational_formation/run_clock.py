"""The run's own time in a recorded bag (render_bag.py): which part of a bag is the run, and a
copy of that part on the run's clock.

The run's time is the status's `time`, t_k = k h from the run's first step, which the status
text on screen shows. A lockstep bag's time and stamps are that simulated time already. A timed
or robots bag (record_formation.py: rosbag record) is on wall time twice over: its stamps are
the ROS time at which each message was published, and its bag time is the time at which rosbag
record received it. A 30 s run of 7 unicycles (ring7, 3000 steps, on a loaded 2-core machine)
gave a 31.05 s bag: 0.52 s before step 0 (the robots publish while the agents wait for the
start), 0.20 s after the last step (until the launch stopped the recorder), 30.33 s of wall time
for the run's 30 s (the ticks of wall timers come late under load), and messages received up to
1.1 s after their stamps (rosbag record's queues, in bursts). A video on the bag's time shows
all four; on the run's clock it shows none.
"""
import numpy as np

from variational_formation.cli import fail

LATE_MAX = 10.0  # [s] how long after its stamp a message may have reached the bag
EARLY_MAX = 1.0  # [s] how long before: clocks of two hosts that differ


def stamped_headers(msg):
    """The headers of a message the render replays: its own, its transforms' or its markers'."""
    headers = [msg.header] if hasattr(msg, "header") else []
    return headers + [m.header for m in getattr(msg, "transforms", []) + getattr(msg, "markers", [])]


class RunSpan:
    """The part [start, end] of the run (seconds of its own time) that a bag holds, as the bag
    times first..last to replay: of the recorded bag where its stamps are the run's time (or
    where it has no status: then the whole bag, in seconds from its start), else of the copy
    that write_on_run_time makes.

    The span runs from the markers of the first shown step to those of the last (stamped like
    that step's status; the status itself where the bag has no markers)."""

    def __init__(self, contents, status, markers, start, end):
        import rosbag
        self.start, self.end = start, end  # run time [s]
        self.on_wall_time = False
        if status not in contents.topics:
            length = contents.end - contents.start
            if start >= length:
                fail(f"--from {start}: the bag lasts only {length:.3f} s")
            self.end = length if end is None else min(end, length)
            self.first, self.last = contents.start + start, contents.start + self.end  # bag time [s]
            return
        steps = []  # (t_k, header stamp [ns]) of each status, in bag order
        received = {status: {}, markers: {}}  # topic: {header stamp [ns]: bag times [s]}
        for path in contents.parts:
            with rosbag.Bag(path) as bag:
                for topic, msg, t in bag.read_messages(topics=[status] + ([markers] if markers else [])):
                    if topic == status:
                        stamp = msg.header.stamp.to_nsec()
                        steps.append((msg.time, stamp))
                    elif msg.markers:
                        stamp = msg.markers[0].header.stamp.to_nsec()
                    else:
                        continue
                    received[topic].setdefault(stamp, []).append(t.to_sec())
        # In the run's order: a burst received late puts earlier steps after later ones in the bag.
        shown = sorted((time, stamp) for time, stamp in steps if time >= start and (end is None or time <= end))
        # From and to a step with markers, where the bag has them: rosbag record may subscribe to
        # the status a step before it does to the markers.
        shown = [s for s in shown if s[1] in received[markers]] or shown
        if not shown:
            fail(f"--from {start}: the run's status in the bag covers {steps[0][0]:.3f} to {steps[-1][0]:.3f} s"
                 if steps else f"{status}: no status message in the bag")
        (self.start, first), (self.end, last) = shown[0], shown[-1]
        # The run's clock: t_k at each status's stamp (the newest step where stamps repeat).
        clock = {}
        for time, stamp in steps:
            clock[stamp * 1e-9] = max(time, clock.get(stamp * 1e-9, time))
        self.stamps = np.array(sorted(clock))
        self.times = np.array([clock[s] for s in self.stamps])
        self.on_wall_time = bool(np.any(np.abs(self.stamps - self.times) > 1e-3))
        if self.on_wall_time:
            # Compared in nanoseconds: at today's epoch a stamp in seconds is rounded to 0.24 us,
            # and stamp.to_sec() and nsec * 1e-9 round it differently (the first or last step's
            # markers fell out of the copy).
            self.first_ns, self.last_ns = first, last
            self.first_stamp, self.last_stamp = first * 1e-9, last * 1e-9
            first_time, last_time = self.start, self.end
        else:
            first_time = min(received[markers].get(first) or received[status][first])
            last_time = max(received[markers].get(last) or received[status][last])
        # A microsecond wider: bag times go through floating point on their way to rosbag play.
        self.first, self.last = max(0.0, first_time - 1e-6), last_time + 1e-6

    def run_time(self, stamp):
        """The run's time [s] at a wall-time stamp [s]: between the statuses' stamps, linear."""
        return float(np.interp(stamp, self.stamps, self.times))

    def write_on_run_time(self, contents, topics, path):
        """A bag at `path` of what `topics` published during the span, stamped and timed with the
        run's time of its stamp (a message's time is that of its newest stamp, or, unstamped,
        of its reception): replayed, it shows each message when it was published, at the run's
        pace. /tf_static goes in whole, at the span's start."""
        import rosbag
        import rospy
        window = {"start_time": rospy.Time.from_sec(self.first_stamp - EARLY_MAX),
                  "end_time": rospy.Time.from_sec(self.last_stamp + LATE_MAX)}
        copied = []
        for part in contents.parts:
            with rosbag.Bag(part) as bag:
                for topic in topics:
                    static = topic == "/tf_static"
                    for _, msg, t in bag.read_messages(topics=[topic], **({} if static else window)):
                        headers = [h for h in stamped_headers(msg) if not h.stamp.is_zero()]
                        stamp = max([h.stamp.to_nsec() for h in headers] or [t.to_nsec()])
                        if not static and not self.first_ns <= stamp <= self.last_ns:
                            continue
                        for h in headers:
                            h.stamp = rospy.Time.from_sec(self.run_time(h.stamp.to_nsec() * 1e-9))
                        copied.append((self.start if static else self.run_time(stamp * 1e-9), len(copied), topic,
                                       msg))
        copied.sort(key=lambda c: c[:2])
        with rosbag.Bag(path, "w") as out:
            for time, _, topic, msg in copied:
                out.write(topic, msg, rospy.Time.from_sec(time))
