"""Each of the repository's three packages declares in its package.xml what it uses, with a type
that covers the use: the C++ includes, the Python imports, find_package() and the launch files'
pkg= are cross-checked, so a new use without a declaration fails here. Every declared key that is
not one of the three packages has a line in scripts/debian_packages.txt (the apt list of
scripts/common.sh). And the boundary: variational_formation_core declares and finds nothing of
ROS, variational_formation_msgs only what messages need."""
import glob
import os
import re
import sys
import unittest
import xml.etree.ElementTree as ElementTree

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from vf_harness import REPO  # noqa: E402

ROOT = os.path.dirname(REPO)
PACKAGES = {name: os.path.join(ROOT, name)
            for name in ("variational_formation", "variational_formation_core", "variational_formation_msgs")}

BUILD = ("depend", "build_depend", "buildtool_depend")
EXEC = ("depend", "exec_depend")
TEST = ("test_depend",)
# An include folder or Python module that is not named after its rosdep key.
INCLUDE_KEYS = {"Eigen": "eigen", "yaml-cpp": "yaml-cpp", "gtest": "gtest", "benchmark": "benchmark",
                "mujoco": "libmujoco-dev", "ros": "roscpp", "XmlRpc": "roscpp", "variational_formation": None,
                "variational_formation_core": "variational_formation_core"}
SYSTEM_INCLUDES = {"sys", "arpa", "netinet", "bits"}  # the C library
PYTHON_KEYS = {"numpy": "python3-numpy", "yaml": "python3-yaml", "matplotlib": "python3-matplotlib",
               "rospkg": "python3-rospkg", "variational_formation": None}
FIND_PACKAGE_KEYS = {"Eigen3": "eigen", "yaml-cpp": "yaml-cpp", "Threads": None, "benchmark": "benchmark",
                     "catkin": "catkin", "mujoco": "libmujoco-dev"}


def declared(package):
    """{key: set of dependency tags} of one package's package.xml."""
    keys = {}
    for element in ElementTree.parse(os.path.join(PACKAGES[package], "package.xml")).getroot():
        if element.tag.endswith("depend"):
            keys.setdefault(element.text.strip(), set()).add(element.tag)
    return keys


class DependenciesTest(unittest.TestCase):
    """Every check runs over each package in turn (self.package, self.root)."""

    def setUp(self):
        self.missing = []

    def each_package(self):
        for package, root in PACKAGES.items():
            self.package, self.root, self.keys = package, root, declared(package)
            yield package

    def files(self, *patterns):
        for pattern in patterns:
            yield from sorted(glob.glob(os.path.join(self.root, pattern), recursive=True))

    def relative(self, path):
        return os.path.relpath(path, ROOT)

    def need(self, key, tags, where):
        if key is not None and key != self.package and not self.keys.get(key, set()) & set(tags):
            self.missing.append(f"{where}: uses '{key}', which {self.package}/package.xml must declare "
                                f"as one of {', '.join(tags)}")

    def tearDown(self):
        self.assertEqual(self.missing, [], "\n".join(self.missing))

    def test_cpp_includes(self):
        standard = set()
        for _ in self.each_package():
            for path in self.files("include/**/*.hpp", "src/**/*.cpp", "test/**/*.cpp", "test/**/*.hpp", "benchmark/*.cpp"):
                relative = self.relative(path)
                tags = TEST + BUILD if os.path.relpath(path, self.root).startswith(("test/", "benchmark/")) else BUILD
                with open(path) as f:
                    for folder in re.findall(r'^\s*#\s*include\s*<([^>/]+)/', f.read(), re.M):
                        if folder in SYSTEM_INCLUDES:
                            continue
                        self.need(INCLUDE_KEYS.get(folder, folder), tags, relative)
                    standard.add(relative)
        self.assertGreater(len(standard), 50)

    def test_python_imports(self):
        for _ in self.each_package():
            local = {os.path.splitext(os.path.basename(p))[0] for p in self.files("scripts/*.py", "test/**/*.py")}
            for path in self.files("scripts/*.py", "src/variational_formation/*.py", "test/**/*.py"):
                relative = self.relative(path)
                tags = TEST + EXEC if os.path.relpath(path, self.root).startswith("test/") else EXEC
                with open(path) as f:
                    for module in re.findall(r'^\s*(?:import|from)\s+([A-Za-z_][A-Za-z_0-9]*)', f.read(), re.M):
                        if module in sys.stdlib_module_names or module in local:
                            continue
                        self.need(PYTHON_KEYS.get(module, module), tags, relative)

    def test_find_package(self):
        for _ in self.each_package():
            for path in self.files("CMakeLists.txt", "cmake/*.cmake"):
                with open(path) as f:
                    text = f.read()
                relative = self.relative(path)
                for name, rest in re.findall(r'find_package\(\s*([^\s)]+)([^)]*)\)', text):
                    tags = TEST + BUILD if name == "rostest" else BUILD
                    self.need(FIND_PACKAGE_KEYS.get(name, name), tags, relative)
                    if "COMPONENTS" in rest:
                        for component in rest.split("COMPONENTS", 1)[1].split():
                            self.need(component, BUILD, relative)

    def test_launch_packages(self):
        for _ in self.each_package():
            for path in self.files("launch/**/*.launch", "test/**/*.test", "test/**/*.launch"):
                relative = self.relative(path)
                tags = TEST + EXEC if os.path.relpath(path, self.root).startswith("test/") else EXEC
                with open(path) as f:
                    text = f.read()
                for value in re.findall(r'\bpkg="([^"]+)"', text):
                    # pkg="$(eval 'a' if x else 'b')": every quoted name.
                    for key in re.findall(r"'([A-Za-z_0-9]+)'", value) if value.startswith("$(") else [value]:
                        self.need(key, tags, relative)

    def test_every_key_maps_to_debian_packages(self):
        mapping = {}
        with open(os.path.join(REPO, "scripts", "debian_packages.txt")) as f:
            for line in f:
                if line.strip() and not line.startswith("#"):
                    key, _, packages = line.partition(":")
                    self.assertNotIn(key, mapping, f"{key} mapped twice")
                    mapping[key] = packages.split()
        keys = set()
        for package in PACKAGES:
            keys |= set(declared(package)) - set(PACKAGES)
        for key in sorted(keys):
            self.assertTrue(mapping.get(key), f"package.xml key {key} has no Debian packages")
        self.assertEqual(sorted(set(mapping) - keys), [], "mapped keys no package.xml declares")


class PackageBoundaryTest(unittest.TestCase):
    """The package boundary, read from package.xml and CMake: the core is ROS-free by what it
    declares and what it finds, not only by what its files include (test_layers)."""

    def test_core_declares_only_eigen_and_yaml_cpp(self):
        keys = declared("variational_formation_core")
        self.assertEqual(keys, {"catkin": {"buildtool_depend"}, "eigen": {"depend"}, "yaml-cpp": {"depend"}})

    def test_core_finds_no_catkin_component(self):
        with open(os.path.join(PACKAGES["variational_formation_core"], "CMakeLists.txt")) as f:
            text = f.read()
        found = re.findall(r'find_package\(\s*([^\s)]+)([^)]*)\)', text)
        self.assertEqual(sorted(name for name, _ in found), ["Eigen3", "Threads", "catkin", "yaml-cpp"])
        self.assertEqual([rest for name, rest in found if "COMPONENTS" in rest], [],
                         "the core finds catkin without components: no ROS package reaches it")
        self.assertNotRegex(text, r"catkin_(INCLUDE_DIRS|LIBRARIES)", "the core uses nothing catkin found")
        self.assertNotRegex(text, r"CATKIN_DEPENDS", "the core exports no ROS dependency")

    def test_messages_declare_only_what_messages_need(self):
        keys = set(declared("variational_formation_msgs"))
        self.assertEqual(keys, {"catkin", "message_generation", "message_runtime", "geometry_msgs", "std_msgs"})

    def test_nodes_reach_the_core_and_messages_as_packages(self):
        keys = declared("variational_formation")
        for package in ("variational_formation_core", "variational_formation_msgs"):
            self.assertIn("depend", keys.get(package, set()), package)
        self.assertNotIn("message_generation", keys, "the messages are generated in variational_formation_msgs")


if __name__ == "__main__":
    unittest.main()
