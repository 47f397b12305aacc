#!/usr/bin/python3
"""Hosts for the multi-host tests (multihost_test.py, sharded_test.py): Linux network namespaces,
one per host, joined by veth pairs to a bridge in a namespace of its own, each host with its own
address in a /24 and its own ROS_IP / ROS_HOSTNAME; no interface or route of the root namespace
is touched. Everything a `Hosts` made (namespaces, veths, the bridge, the processes started in
them) goes with `down()`, which the tests call in `finally`.

Also the probes: small ROS clients that run inside a host (the root namespace cannot reach the
hosts' addresses) and print one JSON line:
`vf_netns.py --probe master|graph|publishers|connections|step ...`.
Needs root (CAP_SYS_ADMIN and CAP_NET_ADMIN); without it `up()` fails, saying so.
"""
import contextlib
import fcntl
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

IP = shutil.which("ip") or next((p for p in ("/usr/sbin/ip", "/sbin/ip") if os.path.exists(p)), "ip")
PROBE = os.path.abspath(__file__)


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


class Hosts:
    """Hosts named by `numbers` ({"A": 1, "B": 2, ...}; A holds the master): network namespaces
    <prefix><port>_a, _b, ..., each with `lo` up and an eth0 (a veth whose other end is on the
    bridge br0 of the namespace <prefix><port>_br), at <subnet>.<number>/24. Processes run in
    them through `ip netns exec` with that host's ROS_IP, ROS_HOSTNAME and the master on A.
    `label` names the test in messages and in the lock file (one run per port at a time)."""

    def __init__(self, port, workdir, subnet, numbers, prefix, label):
        self.port, self.workdir, self.subnet, self.numbers, self.label = port, workdir, subnet, dict(numbers), label
        self.prefix = f"{prefix}{port}"
        self.ns = {h: f"{self.prefix}_{h.lower()}" for h in self.numbers}
        self.bridge = f"{self.prefix}_br"
        self.procs, self.logs = [], {}
        self.master = self.lock = None

    def address(self, host):
        return f"{self.subnet}.{self.numbers[host]}"

    def all_namespaces(self):
        return [self.bridge, *self.ns.values()]

    def env(self, host):
        return dict(os.environ, ROS_IP=self.address(host), ROS_HOSTNAME=self.address(host),
                    ROS_MASTER_URI=f"http://{self.address('A')}:{self.port}",
                    ROS_LOG_DIR=os.path.join(self.workdir, "ros_log"))

    def up(self):
        # One run per port at a time: a second one waits here instead of removing the first's hosts.
        self.lock = os.open(os.path.join(tempfile.gettempdir(), f"vf_{self.label}_{self.port}.lock"),
                            os.O_RDONLY | os.O_CREAT, 0o644)
        fcntl.flock(self.lock, fcntl.LOCK_EX)
        self.remove_namespaces()  # leftovers of an interrupted run
        if not os.path.exists(IP) and not shutil.which(IP):
            raise AssertionError(f"{self.label}: the `ip` command (Debian package iproute2) is missing")
        made = ip("netns", "add", self.bridge, check=False)
        if made.returncode != 0:
            raise AssertionError(
                f"{self.label}: cannot create a network namespace (`ip netns add {self.bridge}`: "
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
            ip("-n", ns, "addr", "add", f"{self.address(host)}/24", "dev", "eth0")
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
            # Deleting a namespace deletes its veth ends, and with them their peers on the bridge.
            ip("netns", "del", ns, check=False)

    def leftovers(self):
        """What of this run's namespaces is still there (for a test that checks its clean-up)."""
        present = ip("netns", "list", check=False).stdout.split()
        return [ns for ns in self.all_namespaces() if ns in present]

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
        """A probe of this file (--probe) on host A (the test itself runs outside the hosts)."""
        run = self.run("A", ["/usr/bin/python3", PROBE, "--probe", *args], timeout)
        if run.returncode != 0:
            raise AssertionError(f"probe {args} on host A failed: {run.stdout[-2000:]}{run.stderr[-2000:]}")
        return json.loads(run.stdout.strip().splitlines()[-1])

    def start_master(self):
        self.master = self.start("A", "roscore", ["roscore", "-p", str(self.port)])
        self.probe("master", timeout=40.0)

    def host_of_pid(self, pid):
        """The host whose network namespace holds process `pid` (None: none of them)."""
        try:
            mine = os.stat(f"/proc/{pid}/ns/net").st_ino
        except OSError:
            return None
        for host, ns in self.ns.items():
            with contextlib.suppress(OSError):
                if os.stat(f"/run/netns/{ns}").st_ino == mine:
                    return host
        return None

    def start_watcher(self, topic, step, timeout, name="watch"):
        """A subscriber on host A to the AgentState `topic`, started before the run; once it is
        subscribed its log says "watching". True if it says so within 30 s."""
        watcher = self.start("A", name, ["/usr/bin/python3", PROBE, "--probe", "step", topic, str(step), str(timeout)])
        end = time.time() + 30
        while "watching" not in self.log(name) and watcher.poll() is None and time.time() < end:
            time.sleep(0.1)
        return "watching" in self.log(name)

    def watched_step(self, timeout, name="watch"):
        """The newest step the watcher saw once it saw its step (or gave up): None if it said
        nothing within `timeout` seconds."""
        found = self.answer(name, timeout)
        return found["step"] if found else None

    def start_connections(self, nodes, topics, timeout, name="connections"):
        """A probe on host A that samples the connections of `nodes` until each has a live
        inbound one on every topic of `topics` (or `timeout` seconds pass): for nodes that are
        up only during a run. Its answer: answer(name, ...)."""
        return self.start("A", name, ["/usr/bin/python3", PROBE, "--probe", "connections", str(timeout),
                                      ",".join(nodes), *topics])

    def answer(self, name, timeout):
        """The JSON line a probe started with start() printed, once it has (None: not within
        `timeout` seconds)."""
        # The whole log: the JSON line may be longer than log()'s usual tail.
        end = time.time() + timeout
        while not re.search(r"^\{.*\}$", self.log(name, 0), re.M) and time.time() < end:
            time.sleep(0.01)
        found = re.search(r"^\{.*\}$", self.log(name, 0), re.M)
        return json.loads(found.group(0)) if found else None


def finish_run(run, result_path, timeout):
    """Waits up to `timeout` seconds for the launch `run` to end (then ends it: the monitor writes
    why it was still waiting); returns (the result file as a dict, {} if none; "" or why late)."""
    import yaml
    try:
        run.wait(timeout=timeout)
        late = ""
    except subprocess.TimeoutExpired:
        kill_group(run)
        late = f"the run did not end within {timeout:.0f} s; "
    result = {}
    if os.path.exists(result_path):
        with open(result_path) as f:
            result = yaml.safe_load(f) or {}
    return result, late


# --- Probes: run on a host, print one JSON line --------------------------------------------------

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


def probe_publishers(topics):
    """The master's publishers of each topic (its getSystemState), and the parameters in
    `topics` that start with "param:" (their values, None if unset)."""
    import rosgraph
    master = rosgraph.Master("/multihost_probe")
    publishers = dict(master.getSystemState()[0])
    out = {}
    for topic in topics:
        if topic.startswith("param:"):
            name = topic[len("param:"):]
            out[topic] = master.getParam(name) if master.hasParam(name) else None
        else:
            out[topic] = sorted(publishers.get(topic, []))
    return out


def probe_connections(timeout, nodes, topics):
    """Samples each node's URI, pid and connections (getBusInfo) every 50 ms until every node has
    a live inbound connection on each of `topics`, or `timeout` seconds pass: the sample that
    had them all (else the newest one), and "complete"."""
    import socket
    import xmlrpc.client

    import rosgraph
    socket.setdefaulttimeout(5.0)  # a node that ends while asked does not hold the probe
    master = rosgraph.Master("/multihost_probe")
    end = time.time() + timeout
    out = {}
    while True:
        for name in nodes:
            if out.get(name, {}).get("complete"):
                continue
            try:
                uri = master.lookupNode(name)
                node = xmlrpc.client.ServerProxy(uri)
                sample = {"uri": uri, "pid": node.getPid("/multihost_probe")[2],
                          "bus": node.getBusInfo("/multihost_probe")[2]}
            except Exception as e:
                out.setdefault(name, {"complete": False})["error"] = repr(e)
                continue
            live = {c[4] for c in sample["bus"] if c[2] == "i" and c[5]}
            samples = out.get(name, {}).get("samples", 0) + 1
            out[name] = dict(sample, complete=set(topics) <= live, samples=samples)
        if (len(out) == len(nodes) and all(v["complete"] for v in out.values())) or time.time() > end:
            return out
        time.sleep(0.05)


def probe_step(topic, step, timeout):
    """Waits until an agent's state on `topic` reaches `step`; the newest step seen."""
    import threading

    import rospy
    from variational_formation_msgs.msg import AgentState
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
    elif args[0] == "publishers":
        result = probe_publishers(args[1:])
    elif args[0] == "connections":
        result = probe_connections(float(args[1]), args[2].split(","), args[3:])
    else:
        result = probe_step(args[1], int(args[2]), float(args[3]))
    print(json.dumps(result))


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--probe":
        probe_main(sys.argv[2:])
        sys.exit(0)
    print(__doc__)
