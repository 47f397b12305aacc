#!/usr/bin/python3
"""Multi-host run (catkin_make run_tests, as root): the agents of one hexagon on three hosts that
share one master. The hosts are Linux network namespaces joined by veth pairs to a bridge in a
fourth one, each with its own address in 10.213.50.0/24 and its own ROS_IP / ROS_HOSTNAME; no
interface or route of the root namespace is touched.

- host A (10.213.50.1): the master (roscore) and formation.launch agents:=false record:=true;
- host B (10.213.50.2): agents 0, 2, 4; host C (10.213.50.3): agents 1, 3, 5, each agent by its
  own `roslaunch agent.launch id:=I`.

Checks: the run succeeds, the bag is complete and equals simulate bit for bit, and every agent's
node lives on its host's address with real TCP connections to its neighbours on the other host.
A second case SIGKILLs one agent on host B at a seeded random step, with respawn:=true, and
expects the same (it needs crash recovery in the agent and the monitor). A third loads
launch/examples/several_hosts.launch (machine tags) and checks that it puts one agent on each robot.

Without permission for `ip netns` (not root) the test fails, saying so.

  multihost_test.py [--gtest_output=xml:PATH]      the tests (rosunit)
  multihost_test.py --benchmark [--steps N]        lockstep throughput, 3 hosts against 1 host
"""
import argparse
import contextlib
import fcntl
import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
import xml.etree.ElementTree as ElementTree

import rospkg
import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_rostest  # noqa: E402

PKG = vf_rostest.PKG
SCENARIO = "hexagon"
SUBNET = "10.213.50"
HOST_NUMBER = {"A": 1, "B": 2, "C": 3}
AGENTS_ON = {"B": (0, 2, 4), "C": (1, 3, 5)}
# Master ports (per namespace, but kept apart anyway): one per test case and benchmark run.
PORT_RUN, PORT_KILL, PORT_BENCH_HOSTS, PORT_BENCH_ONE = 11750, 11751, 11752, 11753
RUN_TIMEOUT = 30.0  # seconds from formation.launch's start; a run takes a few (4.2 s at rate 1)


def address(host):
    return f"{SUBNET}.{HOST_NUMBER[host]}"


def host_of(agent):
    return next(h for h, ids in AGENTS_ON.items() if agent in ids)


IP = shutil.which("ip") or next((p for p in ("/usr/sbin/ip", "/sbin/ip") if os.path.exists(p)), "ip")


def ip(*args, check=True):
    return subprocess.run([IP, *args], capture_output=True, text=True, check=check)


def kill_group(*procs, timeout=15.0):
    """SIGINT to process groups we started (roslaunch shuts its nodes down), all at once, then
    SIGKILL to those still there after `timeout` seconds."""
    running = [p for p in procs if p.poll() is None]
    for proc in running:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGINT)
    end = time.time() + timeout
    for proc in running:
        try:
            proc.wait(timeout=max(0.1, end - time.time()))
        except subprocess.TimeoutExpired:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=5)


def descendants(pid):
    """Every process below `pid`, by the parent ids in /proc."""
    children = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            with contextlib.suppress(OSError):
                with open(f"/proc/{entry}/stat") as f:
                    ppid = int(f.read().rsplit(")", 1)[1].split()[1])
                children.setdefault(ppid, []).append(int(entry))
    found, todo = [], [pid]
    while todo:
        for c in children.get(todo.pop(), []):
            found.append(c)
            todo.append(c)
    return found


def executable_of(pid):
    with contextlib.suppress(OSError):
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            return f.read().split(b"\0")[0].decode()
    return ""


def report(line):
    """To the test's output: the JUnit file (rosunit captures stdout) and the console."""
    for stream in {sys.stdout, sys.__stdout__}:
        print(line, file=stream, flush=True)


def monitor_rate(log):
    """(steps, seconds, steps/s) of the monitor's final line, or None."""
    m = re.search(r"monitor: (\d+) steps in ([0-9.]+) s: (\d+) steps/s", log)
    return (int(m.group(1)), float(m.group(2)), float(m.group(3))) if m else None


class Hosts:
    """Three hosts A, B, C: network namespaces vfmh<port>_a/_b/_c, each with `lo` up and an eth0
    (a veth whose other end is on the bridge br0 of the namespace vfmh<port>_br). Processes run
    in them through `ip netns exec` with that host's ROS_IP, ROS_HOSTNAME and the master on A."""

    def __init__(self, port, workdir):
        self.port, self.workdir = port, workdir
        self.prefix = f"vfmh{port}"
        self.ns = {h: f"{self.prefix}_{h.lower()}" for h in HOST_NUMBER}
        self.bridge = f"{self.prefix}_br"
        self.procs, self.logs = [], {}
        self.master = self.lock = None

    def all_namespaces(self):
        return [self.bridge, *self.ns.values()]

    def env(self, host):
        return dict(os.environ, ROS_IP=address(host), ROS_HOSTNAME=address(host),
                    ROS_MASTER_URI=f"http://{address('A')}:{self.port}",
                    ROS_LOG_DIR=os.path.join(self.workdir, "ros_log"))

    def up(self):
        # One run per port at a time: a second one waits here instead of removing the first's hosts.
        self.lock = os.open(os.path.join(tempfile.gettempdir(), f"vf_multihost_{self.port}.lock"),
                            os.O_RDONLY | os.O_CREAT, 0o644)
        fcntl.flock(self.lock, fcntl.LOCK_EX)
        self.remove_namespaces()  # leftovers of an interrupted run
        if not os.path.exists(IP) and not shutil.which(IP):
            raise AssertionError("multihost: the `ip` command (Debian package iproute2) is missing")
        made = ip("netns", "add", self.bridge, check=False)
        if made.returncode != 0:
            raise AssertionError(
                f"multihost: cannot create a network namespace (`ip netns add {self.bridge}`: "
                f"{made.stderr.strip()}); this test needs root (CAP_SYS_ADMIN and CAP_NET_ADMIN), as in CI")
        ip("-n", self.bridge, "link", "set", "lo", "up")
        ip("-n", self.bridge, "link", "add", "br0", "type", "bridge")
        ip("-n", self.bridge, "link", "set", "br0", "up")
        for host, ns in self.ns.items():
            ip("netns", "add", ns)
            port = f"v{host.lower()}"
            ip("-n", self.bridge, "link", "add", port, "type", "veth", "peer", "name", "eth0", "netns", ns)
            ip("-n", self.bridge, "link", "set", port, "master", "br0", "up")
            ip("-n", ns, "link", "set", "lo", "up")
            ip("-n", ns, "addr", "add", f"{address(host)}/24", "dev", "eth0")
            ip("-n", ns, "link", "set", "eth0", "up")

    def remove_namespaces(self):
        present = ip("netns", "list", check=False).stdout.split()
        for ns in self.all_namespaces():
            if ns not in present:
                continue
            # Whatever still runs in it was started by an earlier run of this test: end it by id.
            for pid in ip("netns", "pids", ns, check=False).stdout.split():
                with contextlib.suppress(ProcessLookupError, ValueError):
                    os.kill(int(pid), signal.SIGKILL)
            ip("netns", "del", ns, check=False)

    def down(self):
        # The nodes first, so that they can still unregister, then the master.
        kill_group(*[p for p in self.procs if p is not self.master])
        kill_group(*self.procs)
        self.remove_namespaces()
        if self.lock is not None:
            os.close(self.lock)
            self.lock = None

    def start(self, host, name, cmd):
        """A process on `host`, its output in workdir/<name>.log."""
        path = os.path.join(self.workdir, name + ".log")
        with open(path, "w") as log:
            proc = subprocess.Popen([IP, "netns", "exec", self.ns[host], *cmd], env=self.env(host), stdout=log,
                                    stderr=subprocess.STDOUT, start_new_session=True)
        self.procs.append(proc)
        self.logs[name] = path
        return proc

    def run(self, host, cmd, timeout):
        return subprocess.run([IP, "netns", "exec", self.ns[host], *cmd], env=self.env(host), capture_output=True,
                              text=True, timeout=timeout)

    def log(self, name, tail=3000):
        with open(self.logs[name], errors="replace") as f:
            text = re.sub(r"\x1b\[[0-9;]*m|\x1b\]2;[^\x07]*\x07", "", f.read())
        return text[-tail:] if tail else text

    def probe(self, *args, timeout=30.0):
        """This script's --probe mode on host A (the test itself runs outside the hosts)."""
        run = self.run("A", ["/usr/bin/python3", os.path.abspath(__file__), "--probe", *args], timeout)
        if run.returncode != 0:
            raise AssertionError(f"probe {args} on host A failed: {run.stdout[-2000:]}{run.stderr[-2000:]}")
        return json.loads(run.stdout.strip().splitlines()[-1])

    def start_master(self):
        self.master = self.start("A", "roscore", ["roscore", "-p", str(self.port)])
        self.probe("master", timeout=40.0)

    def start_agents(self, scenario, *extra):
        return {i: self.start(host, f"agent_{i}", ["roslaunch", PKG, "agent.launch", f"id:={i}",
                                                   f"scenario:={scenario}", *extra])
                for host, ids in AGENTS_ON.items() for i in ids}


# --- Probes: run on host A, print one JSON line --------------------------------------------------

def probe_master(timeout=35.0):
    import rosgraph
    end = time.time() + timeout
    while True:
        try:
            return {"pid": rosgraph.Master("/multihost_probe").getPid()}
        except Exception:
            if time.time() > end:
                raise
            time.sleep(0.2)


def probe_graph(names, timeout=40.0):
    """Each node's URI and pid and its live connections (roscpp's getBusInfo), once all are up."""
    import xmlrpc.client

    import rosgraph
    master = rosgraph.Master("/multihost_probe")
    end = time.time() + timeout
    out = {}
    for name in names:
        while True:
            try:
                uri = master.lookupNode(name)
                node = xmlrpc.client.ServerProxy(uri)
                out[name] = {"uri": uri, "pid": node.getPid("/multihost_probe")[2],
                             "bus": node.getBusInfo("/multihost_probe")[2]}
                break
            except Exception:
                if time.time() > end:
                    raise
                time.sleep(0.2)
    return out


def probe_step(topic, step, timeout):
    """Waits until an agent's state on `topic` reaches `step`; the newest step seen."""
    import threading

    import rospy
    from variational_formation.msg import AgentState
    reached, seen = threading.Event(), [-1]

    def on_state(msg):
        seen[0] = max(seen[0], msg.step)
        if seen[0] >= step:
            reached.set()

    rospy.init_node("multihost_watch", anonymous=True, disable_signals=True)
    sub = rospy.Subscriber(topic, AgentState, on_state, queue_size=10000, tcp_nodelay=True)
    print("watching", flush=True)
    reached.wait(timeout)
    print(json.dumps({"step": seen[0]}), flush=True)  # at once: rospy takes a while to shut down
    sub.unregister()
    return {"step": seen[0]}


def probe_main(args):
    if args[0] == "master":
        result = probe_master()
    elif args[0] == "graph":
        result = probe_graph(args[1:])
    else:
        result = probe_step(args[1], int(args[2]), float(args[3]))
    print(json.dumps(result))


# --- The tests -----------------------------------------------------------------------------------

@vf_rostest.reported_setup
class MultiHost(unittest.TestCase, vf_rostest.RunChecks):
    @classmethod
    def setUpClass(cls):
        cls.path = vf_rostest.scenario_path(SCENARIO)
        cls.scenario = vf_rostest.load_scenario(cls.path)
        cls.expected = vf_rostest.simulate(cls.path)

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="vf_multihost_")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def cross_host_problems(self, graph):
        """What is missing for every agent's node to be on its host's address with a live TCP
        connection to each neighbour on the other host, from that host's address."""
        problems = []
        for i in range(self.scenario["n"]):
            info = graph[f"/formation/agent_{i}"]
            if not info["uri"].startswith(f"http://{address(host_of(i))}:"):
                problems.append(f"agent_{i} is at {info['uri']}, not on host {host_of(i)} ({address(host_of(i))})")
            for j in self.scenario["neighbours"][i]:
                topic = f"/formation/agent_{j}/state"
                peers = [c[6] for c in info["bus"] if c[4] == topic and c[2] == "i" and c[5]]
                if host_of(j) != host_of(i) and not any(f"[{address(host_of(j))}:" in p for p in peers):
                    problems.append(f"agent_{i} ({address(host_of(i))}) has no connection to agent_{j} on "
                                    f"{address(host_of(j))}: {peers}")
        return problems

    def check_hosts(self, hosts, names, timeout=30.0):
        """Polls the agents' connections (they connect once their neighbours are up) until every
        cross-host one is there; prints them."""
        end = time.time() + timeout
        while True:
            graph = hosts.probe("graph", *names, timeout=60.0)
            problems = self.cross_host_problems(graph)
            if not problems or time.time() > end:
                break
            time.sleep(0.5)
        self.assertEqual(problems, [])
        for name, info in graph.items():
            peers = sorted({re.sub(r".* to \[([0-9.]+):.*", r"\1", c[6]) for c in info["bus"] if c[2] == "i"})
            report(f"multihost: {name} at {info['uri']}, receives states from {', '.join(peers)}")

    def run_formation(self, hosts, kill=None, victim=None):
        """The run: master and agents first (they wait for the monitor), then formation.launch on
        A. With kill = (step, action), action(agents, seen) runs once the victim has published
        `step` (seen: the newest step a watcher on A has from it). Returns the recording."""
        hosts.start_master()
        respawn = ["respawn:=true", "rate:=1"] if kill else []
        agents = hosts.start_agents(SCENARIO, *respawn)
        self.check_hosts(hosts, [f"/formation/agent_{i}" for i in agents])
        extra = []
        if kill and "respawn_timeout" in formation_args():
            extra.append("respawn_timeout:=20")
        if kill:
            # The watcher subscribes before the run starts, so it sees the step when it comes.
            watcher = hosts.start("A", "watch", ["/usr/bin/python3", os.path.abspath(__file__), "--probe", "step",
                                                 f"/formation/agent_{victim}/state", str(kill[0]), str(RUN_TIMEOUT)])
            end = time.time() + 30
            while "watching" not in hosts.log("watch") and watcher.poll() is None and time.time() < end:
                time.sleep(0.1)
            self.assertIn("watching", hosts.log("watch"), "the step watcher did not start")
        out = os.path.join(self.tmp, "out")
        run = hosts.start("A", "formation", ["rosrun", PKG, "run_formation.sh", f"scenario:={SCENARIO}",
                                             "agents:=false", "record:=true", f"output_dir:={out}", *extra])
        if kill:
            end = time.time() + RUN_TIMEOUT + 10
            while not re.search(r"^\{.*\}$", hosts.log("watch"), re.M) and time.time() < end:
                time.sleep(0.01)
            found = re.search(r"^\{.*\}$", hosts.log("watch"), re.M)
            self.assertTrue(found, f"the step watcher said nothing:\n{hosts.log('watch')}\n{hosts.log('formation')}")
            seen = json.loads(found.group(0))["step"]
            self.assertGreaterEqual(seen, kill[0], f"the run did not reach step {kill[0]}:\n{hosts.log('formation')}")
            self.assertLess(seen, int(self.scenario["steps"]), "the watcher saw the step only after the run")
            kill[1](agents, seen)
        timeout = RUN_TIMEOUT
        try:
            run.wait(timeout=timeout)
            late = ""
        except subprocess.TimeoutExpired:
            kill_group(run)  # the monitor writes why it was still waiting
            late = f"the run did not end within {timeout:.0f} s; "
        result_path = os.path.join(out, SCENARIO + ".result.yaml")
        result = {}
        if os.path.exists(result_path):
            with open(result_path) as f:
                result = yaml.safe_load(f) or {}
        victim_log = f"\nagent_{victim}'s roslaunch:\n{hosts.log(f'agent_{victim}', 1500)}" if kill else ""
        self.assertEqual(result.get("result"), "succeeded",
                         f"{late}result file: {result}\n{hosts.log('formation')}{victim_log}")
        self.assertEqual(run.returncode, 0, hosts.log("formation"))
        # After a run the agents stay up, idle (a respawning node that exited would only be
        # restarted), as on robots: end their launches.
        kill_group(*agents.values())
        for i, proc in agents.items():
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self.fail(f"agent_{i}'s roslaunch on host {host_of(i)} did not end:\n{hosts.log(f'agent_{i}')}")
        rec = vf_rostest.Recording(os.path.join(out, SCENARIO + ".bag"))
        self.check_recording(rec, self.scenario, self.expected)
        return rec

    def test_agents_on_two_hosts_equal_simulate(self):
        hosts = Hosts(PORT_RUN, self.tmp)
        try:
            hosts.up()
            self.run_formation(hosts)
        finally:
            hosts.down()

    def test_agent_killed_on_a_remote_host_respawns_and_the_run_equals_simulate(self):
        # Needs crash recovery: the respawned agent resumes from its newest state held by its
        # neighbours or the monitor, and the monitor waits for it (formation.launch respawn_timeout).
        seed = int(os.environ.get("VF_MULTIHOST_SEED", time.time_ns() % 1_000_000))
        rng = random.Random(seed)
        victim = rng.choice(AGENTS_ON["B"])
        step = rng.randint(10, int(self.scenario["steps"]) - 20)
        killed = {}

        def kill(agents, seen):
            pids = [p for p in descendants(agents[victim].pid) if executable_of(p).endswith("/agent")]
            self.assertEqual(len(pids), 1, f"agent_{victim}'s process under its roslaunch: {pids}")
            os.kill(pids[0], signal.SIGKILL)
            killed.update(pid=pids[0], step=seen)
            report(f"multihost: seed {seed}: SIGKILL to agent_{victim} (pid {pids[0]}) on host B "
                   f"({address('B')}) once it had published step {seen} (drawn: {step}); "
                   f"VF_MULTIHOST_SEED={seed} draws the same")

        hosts = Hosts(PORT_KILL, self.tmp)
        try:
            hosts.up()
            self.run_formation(hosts, (step, kill), victim)
        finally:
            hosts.down()
        self.assertIn("pid", killed, "the agent was not killed")

    def test_example_with_machine_tags_puts_one_agent_on_each_robot(self):
        import roslaunch.config
        path = os.path.join(rospkg.RosPack().get_path(PKG), "launch", "examples", "several_hosts.launch")
        config = roslaunch.config.load_config_default([path], None)
        placed = {n.namespace + n.name: n.machine_name for n in config.nodes}
        n = self.scenario["n"]
        self.assertEqual(sorted(placed), sorted([f"/formation/agent_{i}" for i in range(n)] +
                                                ["/formation/end_of_run", "/formation/monitor", "/formation/recorder"]))
        addresses = {config.machines[placed[f"/formation/agent_{i}"]].address for i in range(n)}
        self.assertEqual(len(addresses), n, "one robot (machine address) per agent")
        self.assertFalse(placed["/formation/monitor"], "the monitor runs beside the master, on no robot")


def formation_args():
    path = os.path.join(rospkg.RosPack().get_path(PKG), "launch", "formation.launch")
    return {a.get("name") for a in ElementTree.parse(path).getroot().iter("arg")}


# --- Benchmark -----------------------------------------------------------------------------------

def benchmark(steps, repeats):
    """Lockstep throughput of a hexagon with `steps` steps, no recording: agents on hosts B and C,
    monitor on A (one namespace host each), against plain formation.launch on loopback."""
    work = tempfile.mkdtemp(prefix="vf_multihost_bench_")
    try:
        s = vf_rostest.load_scenario(vf_rostest.scenario_path(SCENARIO))
        s = {k: v for k, v in s.items() if k not in ("n", "neighbours")}
        s["steps"] = steps
        path = os.path.join(work, f"{SCENARIO}_{steps}.yaml")
        with open(path, "w") as f:
            yaml.safe_dump(s, f)
        rows = []
        for r in range(repeats):
            for setup in ("3 hosts", "1 host"):
                run_dir = os.path.join(work, f"{setup.replace(' ', '_')}_{r}")
                os.makedirs(run_dir)
                measured = bench_hosts(path, run_dir) if setup == "3 hosts" else bench_one(path, run_dir)
                rows.append((setup, measured))
                print(f"  run {r + 1}, {setup}: " + (f"{measured[0]} steps in {measured[1]:.3f} s: "
                                                     f"{measured[2]:.0f} steps/s" if measured else "failed"),
                      flush=True)
        print(f"\nhexagon, {steps} steps, h = {s['time_step']}, no recording, {repeats} runs each "
              f"(median; the monitor's steps/s from step 0 to the last)")
        print(f"{'setup':48} {'steps/s':>10} {'real-time factor':>17}")
        medians = {}
        for setup, label in (("3 hosts", "agents on 2 namespace hosts, monitor on a 3rd"),
                             ("1 host", "all on one host (loopback)")):
            rates = sorted(m[2] for st, m in rows if st == setup and m)
            if not rates:
                print(f"{label:48} {'failed':>10}")
                continue
            medians[setup] = rates[len(rates) // 2]
            print(f"{label:48} {medians[setup]:10.0f} {medians[setup] * s['time_step']:17.1f}")
        if len(medians) == 2:
            print(f"3 hosts / 1 host: {medians['3 hosts'] / medians['1 host']:.2f}")
        return 0 if len(medians) == 2 else 1
    finally:
        shutil.rmtree(work, ignore_errors=True)


def bench_hosts(path, run_dir):
    hosts = Hosts(PORT_BENCH_HOSTS, run_dir)
    try:
        hosts.up()
        hosts.start_master()
        agents = hosts.start_agents(path)
        hosts.probe("graph", *[f"/formation/agent_{i}" for i in agents], timeout=60.0)
        run = hosts.start("A", "formation", ["rosrun", PKG, "run_formation.sh", f"scenario:={path}",
                                             "agents:=false", f"output_dir:={run_dir}"])
        run.wait(timeout=300)
        return monitor_rate(hosts.log("formation", tail=0))
    finally:
        hosts.down()


def bench_one(path, run_dir):
    env = dict(os.environ, ROS_HOSTNAME="localhost", ROS_MASTER_URI=f"http://localhost:{PORT_BENCH_ONE}",
               ROS_LOG_DIR=os.path.join(run_dir, "ros_log"))
    env.pop("ROS_IP", None)
    log_path = os.path.join(run_dir, "formation.log")
    with open(log_path, "w") as log:
        proc = subprocess.Popen(["roslaunch", "-p", str(PORT_BENCH_ONE), PKG, "formation.launch",
                                 f"scenario:={path}", f"output_dir:={run_dir}"], env=env, stdout=log,
                                stderr=subprocess.STDOUT, start_new_session=True)
    try:
        proc.wait(timeout=300)
    finally:
        kill_group(proc)
    with open(log_path, errors="replace") as f:
        return monitor_rate(f.read())


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--probe":
        probe_main(sys.argv[2:])
        sys.exit(0)
    if len(sys.argv) > 1 and sys.argv[1] == "--benchmark":
        parser = argparse.ArgumentParser(description="lockstep throughput: 3 namespace hosts against 1 host")
        parser.add_argument("--benchmark", action="store_true")
        parser.add_argument("--steps", type=int, default=3000)
        parser.add_argument("--repeats", type=int, default=3)
        a = parser.parse_args()
        sys.exit(benchmark(a.steps, a.repeats))
    import rosunit
    rosunit.unitrun(PKG, "multihost", MultiHost)
