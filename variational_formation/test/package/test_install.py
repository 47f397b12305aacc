"""The install space: installed from the built tree (cmake --install with DESTDIR, no second
configure), it holds real files only, every built program and rosrun script, and a shell that
sources only its setup.bash runs the hexagon to a succeeded result (with the source tree hidden
where a mount namespace is allowed) and every installed executable's --help."""
import os
import shutil
import socket
import stat
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from vf_harness import REPO, WS, run  # noqa: E402

PKG = "variational_formation"
# The repository, which holds the three packages (and .ws): what the install must not name.
TREE = os.path.dirname(REPO)


def prefix_of_build():
    with open(os.path.join(WS, "build", "CMakeCache.txt")) as f:
        for line in f:
            if line.startswith("CMAKE_INSTALL_PREFIX:"):
                return line.split("=", 1)[1].strip()
    raise AssertionError("no CMAKE_INSTALL_PREFIX in the build's cache")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class InstallTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = tempfile.mkdtemp(prefix="vf_install_")
        # The built tree's own install rules (the workspace's setup files and the package), into
        # DESTDIR: about a second, where a second configure and build would take minutes.
        result = run(["cmake", "--install", os.path.join(WS, "build")], env=dict(os.environ, DESTDIR=cls.root))
        if result.returncode != 0:
            shutil.rmtree(cls.root, ignore_errors=True)
            raise AssertionError(f"cmake --install failed:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}")
        cls.prefix = cls.root + prefix_of_build()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.root, ignore_errors=True)

    def in_install(self, command, timeout=120, hide_source=False):
        """Runs a bash command in a clean environment that sources only the install space."""
        script = f"set -e; source {self.prefix}/setup.bash; {command}"
        env = {"PATH": "/usr/bin:/bin:/usr/sbin:/sbin", "HOME": os.environ.get("HOME", "/root"),
               "ROS_HOME": os.path.join(self.root, "ros_home"), "ROS_HOSTNAME": "localhost",
               "MPLCONFIGDIR": os.path.join(self.root, "mpl"), "LANG": "C.UTF-8"}
        argv = ["bash", "-c", script]
        if hide_source:
            # A private mount namespace with an empty folder over the repository (its three
            # packages, and .ws: the source, build and devel spaces).
            empty = os.path.join(self.root, "empty")
            os.makedirs(empty, exist_ok=True)
            argv = ["unshare", "--mount", "bash", "-c", f"mount --bind {empty} {TREE} && {script}"]
        return subprocess.run(argv, env=env, capture_output=True, text=True, timeout=timeout)

    def test_only_real_files_that_do_not_point_into_the_tree(self):
        links, mentions = [], []
        for folder, dirs, files in os.walk(self.prefix):
            for name in dirs + files:
                path = os.path.join(folder, name)
                if os.path.islink(path):
                    links.append(os.path.relpath(path, self.prefix))
                # Bytecode caches keep the path they were compiled at, for tracebacks only.
                elif name in files and not name.endswith(".pyc") and os.path.getsize(path) < 1 << 20:
                    with open(path, "rb") as f:
                        text = f.read()
                    # The install prefix itself lies below the repository here (.ws/install).
                    # A workspace configured with its devel space sourced chains to it as an
                    # underlay (_setup_util.py, the CMake config): how it was configured, not
                    # what was installed; the run below hides the devel space as well.
                    text = text.replace(prefix_of_build().encode(), b"").replace(
                        os.path.join(WS, "devel").encode(), b"")
                    if TREE.encode() + b"/" in text:
                        mentions.append(os.path.relpath(path, self.prefix))
        self.assertEqual(links, [], "symbolic links in the install space")
        self.assertEqual(mentions, [], "installed files naming the source tree or workspace")

    def test_every_program_and_rosrun_script_is_installed(self):
        installed = set(os.listdir(os.path.join(self.prefix, "lib", PKG)))
        devel = os.path.join(WS, "devel", "lib", PKG)
        built = {f for f in os.listdir(devel) if os.access(os.path.join(devel, f), os.X_OK)
                 and os.path.isfile(os.path.join(devel, f))}
        # Tests and benchmarks are built for the checkout only.
        expected = {f for f in built if not f.startswith(("test_", "benchmark_"))}
        for name in os.listdir(os.path.join(REPO, "scripts")):
            path = os.path.join(REPO, "scripts", name)
            if not os.access(path, os.X_OK):
                continue
            with open(path) as f:
                checkout_only = "common.sh" in f.read()  # builds the workspace: demo, test, benchmarks
            if not checkout_only:
                expected.add(name)
        self.assertEqual(sorted(expected - installed), [], "not installed")
        # The MuJoCo world's node and tool (and, through their --help below, its shared library).
        self.assertLessEqual({"mujoco_world", "world_step_response"}, installed)
        for name in ("launch/formation.launch", "launch/robots.launch", "launch/agent.launch",
                     "config/hexagon.yaml", "config/formation.rviz", "package.xml", "nodelet_plugins.xml"):
            self.assertTrue(os.path.isfile(os.path.join(self.prefix, "share", PKG, name)), name)

    def test_every_installed_executable_prints_usage(self):
        folder = os.path.join(self.prefix, "lib", PKG)
        names = sorted(f for f in os.listdir(folder) if os.access(os.path.join(folder, f), os.X_OK)
                       and os.path.isfile(os.path.join(folder, f)))
        self.assertGreater(len(names), 15)
        # One shell for all (each by its installed path; rosrun itself is exercised by the run
        # below): per program, a line "=== NAME STATUS" and then its output.
        loop = (f'cd {folder}; for f in {" ".join(names)}; do out="$(./"$f" --help 2>&1)"; '
                'echo "=== $f $?"; echo "$out"; done')
        result = self.in_install(loop, timeout=120)
        self.assertEqual(result.returncode, 0, result.stderr)
        outputs = {}
        for block in result.stdout.split("=== ")[1:]:
            head, _, text = block.partition("\n")
            name, status = head.rsplit(" ", 1)
            outputs[name] = (int(status), text)
        self.assertEqual(sorted(outputs), names)
        for name, (status, text) in outputs.items():
            self.assertEqual(status, 0, f"{name} --help: exit {status}: {text}")
            self.assertRegex(text.lower(), r"usage", f"{name} --help printed no usage")

    def test_python_package_and_messages_import(self):
        result = self.in_install("/usr/bin/python3 -c 'import variational_formation.plots, "
                                 "variational_formation_msgs.msg; print(variational_formation.plots.__file__)'")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertTrue(result.stdout.startswith(self.prefix), result.stdout)

    def test_hexagon_runs_from_the_install_space(self):
        port = free_port()
        out = os.path.join(self.root, "out")
        # Hiding the tree needs a private mount namespace (root with CAP_SYS_ADMIN, as CI's
        # multi-host test needs too); elsewhere the run still uses only the install space's
        # environment, and the test above shows that nothing installed names the tree.
        hide = os.geteuid() == 0 and run(["unshare", "--mount", "true"]).returncode == 0
        if not hide:
            print("the source tree stays visible: no private mount namespace here", file=sys.stderr)
        command = (f"export ROS_MASTER_URI=http://localhost:{port}; "
                   f"rosrun {PKG} run_formation.sh -p {port} scenario:=hexagon output_dir:={out}")
        result = self.in_install(command, timeout=300, hide_source=hide)
        self.assertEqual(result.returncode, 0, f"{result.stdout[-3000:]}\n{result.stderr[-3000:]}")
        with open(os.path.join(out, "hexagon.result.yaml")) as f:
            self.assertIn("result: succeeded", f.read())
        # roslaunch of the other two launch files parses from the install space.
        for launch in ("robots.launch", "agent.launch id:=0 scenario:=hexagon"):
            listed = self.in_install(f"roslaunch --nodes {PKG} {launch}", hide_source=hide)
            self.assertEqual(listed.returncode, 0, listed.stderr)
            self.assertIn("/formation/agent_0", listed.stdout)
        # The MuJoCo world from the install space: robots.launch world:=mujoco starts it, and the
        # installed node builds the hexagon's world and steps it (its parameter check, its model,
        # libmujoco and its own library), ended by a timeout after its start-up line.
        listed = self.in_install(f"roslaunch --nodes {PKG} robots.launch world:=mujoco", hide_source=hide)
        self.assertEqual(listed.returncode, 0, listed.stderr)
        self.assertIn("/formation/world", listed.stdout)
        port = free_port()
        world = self.in_install(
            f"export ROS_MASTER_URI=http://localhost:{port}; roscore -p {port} >/dev/null 2>&1 & core=$!; "
            f"status=0; timeout -s INT 10 rosrun {PKG} mujoco_world _kinematics:=unicycle "
            f"_scenario:=$(rospack find {PKG})/config/hexagon.yaml || status=$?; "
            f"kill -INT $core; wait $core || true; echo \"mujoco_world exit status $status\"", hide_source=hide)
        self.assertIn("6 robots (built)", world.stdout + world.stderr, world.stderr)
        self.assertNotIn("FATAL", world.stdout + world.stderr)
        # Still stepping when the timeout ended it (timeout's status 124), not dead before.
        self.assertIn("mujoco_world exit status 124", world.stdout, world.stderr)


if __name__ == "__main__":
    unittest.main()
