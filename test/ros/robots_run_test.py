#!/usr/bin/python3
"""rostest (robots_run.test): simulated robots (lag 0.1 s, odometry noise 1 cm) driven by
time-driven agents in robot mode form the hexagon.

Checked independently of the agents' own states: from the robots' odometry in the bag, averaged
over the last second (the noise is white, 1 cm), every edge's length is within 1 cm of the
desired one; and the bag holds every robot's nav_msgs/Odometry throughout the run.
"""
import math
import os
import shutil
import subprocess
import sys
import time
import unittest

import rosbag
import rospy
import rostest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402

TOLERANCE = 0.01  # [m] on every edge length, from the robots' averaged odometry


@vf_rostest.reported_setup
class RobotsRun(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("robots_run_test")
        cls.path = rospy.get_param("~scenario")
        cls.out = rospy.get_param("~output_dir")
        cls.scenario = vf_rostest.load_scenario(cls.path)
        name = os.path.basename(cls.path).replace(".yaml", "")
        cls.result = vf_rostest.wait_for_result(os.path.join(cls.out, name + ".result.yaml"), 50.0)
        # Stop the recorder (SIGINT via rosnode kill) so that the bag is closed and indexed.
        subprocess.run(["rosnode", "kill", "/robots_bag"], capture_output=True)
        bag = os.path.join(cls.out, name + "_robots.bag")
        end = time.time() + 10
        while not os.path.exists(bag) and time.time() < end:
            time.sleep(0.2)
        cls.odom = {}
        cls.status = []
        with rosbag.Bag(bag) as b:
            for topic, msg, t in b.read_messages():
                if topic.endswith("/odom"):
                    cls.odom.setdefault(topic, []).append((t.to_sec(), msg))
                elif topic.endswith("/status"):
                    cls.status.append((t.to_sec(), msg))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.out, ignore_errors=True)

    def test_run_ends(self):
        self.assertEqual(self.result.get("result"), "succeeded", f"result file: {self.result}")

    def test_bag_holds_every_robots_odometry(self):
        n = self.scenario["n"]
        self.assertEqual(sorted(self.odom), sorted(f"/formation/robot_{i}/odom" for i in range(n)))
        for topic, msgs in self.odom.items():
            span = msgs[-1][0] - msgs[0][0]
            self.assertGreater(span, 10.0, topic)
            self.assertGreater(len(msgs), 50 * span, f"{topic}: {len(msgs)} messages in {span:.1f} s")  # 100 Hz

    def edge_error(self, t0, t1):
        """Worst |edge length - desired| [m] from each robot's odometry averaged over [t0, t1)."""
        mean = []
        for i in range(self.scenario["n"]):
            window = [m.pose.pose.position for t, m in self.odom[f"/formation/robot_{i}/odom"] if t0 <= t < t1]
            mean.append((sum(p.x for p in window) / len(window), sum(p.y for p in window) / len(window)))
        desired = [a["desired_position"] for a in sorted(self.scenario["agents"], key=lambda a: a["id"])]
        return max(abs(math.dist(mean[a], mean[b]) - math.dist(desired[a], desired[b])) for a, b in self.scenario["edges"])

    def test_robots_form_the_shape(self):
        start = min(msgs[0][0] for msgs in self.odom.values())
        end = min(msgs[-1][0] for msgs in self.odom.values())
        self.assertTrue(self.status, "no status in the bag")
        profile = [self.edge_error(t, t + 1.0) for t in range(int(start), int(end))]
        print("robots: worst edge error per second [m]: " + " ".join(f"{e:.3f}" for e in profile), flush=True)
        # The last second of the run: up to the monitor's last status.
        end = self.status[-1][0]
        worst = self.edge_error(end - 1.0, end)
        print(f"robots: worst edge error {worst:.4f} m from the odometry of the run's last second", flush=True)
        self.assertLess(worst, TOLERANCE)
        last = self.status[-1][1]
        print(f"monitor: last status tick {last.step}, max distance error {last.max_distance_error:.4f} m "
              f"(from the agents' setpoints), congruent {last.converged}", flush=True)


if __name__ == "__main__":
    rostest.rosrun(vf_rostest.PKG, "robots_run", RobotsRun)
