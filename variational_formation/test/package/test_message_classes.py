"""Every message and service type the package's nodes put on the wire loads in Python the way
rostopic, rosservice and rosbag load it (roslib.message.get_message_class / get_service_class):
`rostopic echo /formation/markers` needs visualization_msgs' Python module, which the C++
headers alone do not bring. The types are found in the code, not listed by hand:

- the message headers the C++ nodes include (<pkg/Type.h> of a package with msg/Type.msg),
- the topics a library the nodes use publishes for them (tf2_ros, diagnostic_updater,
  dynamic_reconfigure, roscpp's /rosout), found by the library's header,
- the types the Python scripts import (`from pkg.msg import A, B`),
- the messages package's msg/ and srv/ (variational_formation_msgs, beside this package).
"""
import glob
import os
import re
import unittest

import rospkg
from roslib.message import get_message_class, get_service_class

# Not through vf_harness, which puts src/ first on sys.path: its variational_formation has no
# msg module, and would hide the built one that rostopic finds.
REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
PKG = "variational_formation"
MSGS = "variational_formation_msgs"
MSGS_DIR = os.path.join(os.path.dirname(REPO), MSGS)
# A library header the nodes include, and the types that library publishes or serves for them.
LIBRARY_TYPES = {
    "tf2_ros/transform_broadcaster.h": ["tf2_msgs/TFMessage"],
    "diagnostic_updater/diagnostic_updater.h": ["diagnostic_msgs/DiagnosticArray"],
    "dynamic_reconfigure/server.h": ["dynamic_reconfigure/Config", "dynamic_reconfigure/ConfigDescription"],
    "ros/ros.h": ["rosgraph_msgs/Log"],
}


def sources(*patterns):
    for pattern in patterns:
        for path in sorted(glob.glob(os.path.join(REPO, pattern), recursive=True)):
            with open(path, encoding="utf-8") as f:
                yield os.path.relpath(path, REPO), f.read()


class MessageClassesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.packages = rospkg.RosPack()
        cls.messages, cls.services = {}, {}  # type -> where it was found

    def is_message(self, package, name):
        try:
            return os.path.isfile(os.path.join(self.packages.get_path(package), "msg", name + ".msg"))
        except rospkg.ResourceNotFound:
            return False

    def found_types(self):
        messages = {}
        for where, text in sources("src/**/*.cpp", "include/**/*.hpp"):
            for header in re.findall(r'^\s*#\s*include\s*<([^>]+)>', text, re.M):
                for kind in LIBRARY_TYPES.get(header, []):
                    messages.setdefault(kind, f"{where} (through {header})")
                m = re.fullmatch(r"(\w+)/(\w+)\.h", header)
                if m and m[1] != PKG and self.is_message(m[1], m[2]):
                    messages.setdefault(f"{m[1]}/{m[2]}", where)
        for where, text in sources("scripts/*.py", "src/variational_formation/*.py"):
            for package, names in re.findall(r'^\s*from\s+(\w+)\.msg\s+import\s+([\w, ]+)', text, re.M):
                for name in names.replace(" ", "").split(","):
                    messages.setdefault(f"{package}/{name}", where)
        for path in sorted(glob.glob(os.path.join(MSGS_DIR, "msg", "*.msg"))):
            messages.setdefault(f"{MSGS}/{os.path.basename(path)[:-4]}", f"{MSGS}/msg/")
        services = {f"{MSGS}/{os.path.basename(p)[:-4]}": f"{MSGS}/srv/"
                    for p in glob.glob(os.path.join(MSGS_DIR, "srv", "*.srv"))}
        return messages, services

    def test_the_search_finds_the_nodes_topics(self):
        messages, services = self.found_types()
        for kind in ("visualization_msgs/MarkerArray", "nav_msgs/Odometry", "geometry_msgs/Twist",
                     "tf2_msgs/TFMessage", "diagnostic_msgs/DiagnosticArray", "std_msgs/Float64",
                     "rosgraph_msgs/Clock", f"{MSGS}/FormationStatus", f"{MSGS}/AgentState"):
            self.assertIn(kind, messages)
        self.assertIn(f"{MSGS}/RecallState", services)

    def test_every_type_loads_in_python(self):
        messages, services = self.found_types()
        missing = [f"{kind} (used in {where})" for kind, where in sorted(messages.items())
                   if get_message_class(kind) is None]
        missing += [f"{kind} (service, {where})" for kind, where in sorted(services.items())
                    if get_service_class(kind) is None]
        self.assertEqual(missing, [], "types rostopic/rosservice cannot load (a Python message package is not "
                                      "installed: add it to scripts/debian_packages.txt):\n" + "\n".join(missing))


if __name__ == "__main__":
    unittest.main()
