"""package.xml declares what the package uses, with a type that covers the use: the C++
includes, the Python imports, find_package() and the launch files' pkg= are cross-checked, so a
new use without a declaration fails here. Every declared key has a line in
scripts/debian_packages.txt (the apt list of scripts/common.sh)."""
import glob
import os
import re
import sys
import unittest
import xml.etree.ElementTree as ElementTree

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from vf_harness import REPO  # noqa: E402

BUILD = ("depend", "build_depend", "buildtool_depend")
EXEC = ("depend", "exec_depend")
TEST = ("test_depend",)
# An include folder or Python module that is not named after its rosdep key.
INCLUDE_KEYS = {"Eigen": "eigen", "yaml-cpp": "yaml-cpp", "gtest": "gtest", "benchmark": "benchmark",
                "mujoco": "libmujoco-dev", "ros": "roscpp", "XmlRpc": "roscpp", "variational_formation": None}
SYSTEM_INCLUDES = {"sys", "arpa", "netinet", "bits"}  # the C library
PYTHON_KEYS = {"numpy": "python3-numpy", "yaml": "python3-yaml", "matplotlib": "python3-matplotlib",
               "rospkg": "python3-rospkg", "variational_formation": None}
FIND_PACKAGE_KEYS = {"Eigen3": "eigen", "yaml-cpp": "yaml-cpp", "Threads": None, "benchmark": "benchmark",
                     "catkin": "catkin", "mujoco": "libmujoco-dev"}


def declared():
    """{key: set of dependency tags}."""
    keys = {}
    for element in ElementTree.parse(os.path.join(REPO, "package.xml")).getroot():
        if element.tag.endswith("depend"):
            keys.setdefault(element.text.strip(), set()).add(element.tag)
    return keys


def files(*patterns):
    for pattern in patterns:
        yield from sorted(glob.glob(os.path.join(REPO, pattern), recursive=True))


class DependenciesTest(unittest.TestCase):
    def setUp(self):
        self.keys = declared()
        self.missing = []

    def need(self, key, tags, where):
        if key is not None and not self.keys.get(key, set()) & set(tags):
            self.missing.append(f"{where}: uses '{key}', which package.xml must declare as one of {', '.join(tags)}")

    def tearDown(self):
        self.assertEqual(self.missing, [], "\n".join(self.missing))

    def test_cpp_includes(self):
        standard = set()
        for path in files("include/**/*.hpp", "src/**/*.cpp", "test/**/*.cpp", "test/**/*.hpp", "benchmark/*.cpp"):
            relative = os.path.relpath(path, REPO)
            tags = TEST + BUILD if relative.startswith(("test/", "benchmark/")) else BUILD
            with open(path) as f:
                for folder in re.findall(r'^\s*#\s*include\s*<([^>/]+)/', f.read(), re.M):
                    if folder in SYSTEM_INCLUDES:
                        continue
                    self.need(INCLUDE_KEYS.get(folder, folder), tags, relative)
                standard.add(relative)
        self.assertGreater(len(standard), 50)

    def test_python_imports(self):
        local = {os.path.splitext(os.path.basename(p))[0] for p in files("scripts/*.py", "test/**/*.py")}
        for path in files("scripts/*.py", "src/variational_formation/*.py", "test/**/*.py"):
            relative = os.path.relpath(path, REPO)
            tags = TEST + EXEC if relative.startswith("test/") else EXEC
            with open(path) as f:
                for module in re.findall(r'^\s*(?:import|from)\s+([A-Za-z_][A-Za-z_0-9]*)', f.read(), re.M):
                    if module in sys.stdlib_module_names or module in local:
                        continue
                    self.need(PYTHON_KEYS.get(module, module), tags, relative)

    def test_find_package(self):
        for path in files("CMakeLists.txt", "cmake/*.cmake"):
            with open(path) as f:
                text = f.read()
            relative = os.path.relpath(path, REPO)
            for name, rest in re.findall(r'find_package\(\s*([^\s)]+)([^)]*)\)', text):
                tags = TEST + BUILD if name == "rostest" else BUILD
                self.need(FIND_PACKAGE_KEYS.get(name, name), tags, relative)
                if "COMPONENTS" in rest:
                    for component in rest.split("COMPONENTS", 1)[1].split():
                        self.need(component, BUILD, relative)

    def test_launch_packages(self):
        for path in files("launch/**/*.launch", "test/**/*.test", "test/**/*.launch"):
            relative = os.path.relpath(path, REPO)
            tags = TEST + EXEC if relative.startswith("test/") else EXEC
            with open(path) as f:
                text = f.read()
            for value in re.findall(r'\bpkg="([^"]+)"', text):
                # pkg="$(eval 'a' if x else 'b')": every quoted name.
                for key in re.findall(r"'([A-Za-z_0-9]+)'", value) if value.startswith("$(") else [value]:
                    self.need(None if key == "variational_formation" else key, tags, relative)

    def test_every_key_maps_to_debian_packages(self):
        mapping = {}
        with open(os.path.join(REPO, "scripts", "debian_packages.txt")) as f:
            for line in f:
                if line.strip() and not line.startswith("#"):
                    key, _, packages = line.partition(":")
                    self.assertNotIn(key, mapping, f"{key} mapped twice")
                    mapping[key] = packages.split()
        for key in self.keys:
            self.assertTrue(mapping.get(key), f"package.xml key {key} has no Debian packages")
        self.assertEqual(sorted(set(mapping) - set(self.keys)), [], "mapped keys package.xml does not declare")


if __name__ == "__main__":
    unittest.main()
