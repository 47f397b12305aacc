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

Without permission for `ip netns` (not root) the test fails, saying so. The hosts, the probes
that run inside them and the step watcher are vf_netns.py's, shared with sharded_test.py.

  multihost_test.py [--gtest_output=xml:PATH]      the tests (rosunit)
  multihost_test.py --benchmark [--steps N]        lockstep throughput, 3 hosts against 1 host
"""
import argparse
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
import vf_netns  # noqa: E402
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


# The namespace hosts, their processes and the probes are shared with sharded_test.py.
kill_group, descendants, executable_of, report = (vf_netns.kill_group, vf_netns.descendants,
                                                  vf_netns.executable_of, vf_netns.report)


def monitor_rate(log):
    """(steps, seconds, steps/s) of the monitor's final line, or None."""
    m = re.search(r"monitor: (\d+) steps in ([0-9.]+) s: (\d+) steps/s", log)
    return (int(m.group(1)), float(m.group(2)), float(m.group(3))) if m else None


class Hosts(vf_netns.Hosts):
    """Three hosts A, B, C (vf_netns.Hosts): network namespaces vfmh<port>_a/_b/_c on the bridge
    of vfmh<port>_br, at 10.213.50.1-3."""

    def __init__(self, port, workdir):
        super().__init__(port, workdir, SUBNET, HOST_NUMBER, prefix="vfmh", label="multihost")

    def start_agents(self, scenario, *extra):
        return {i: self.start(host, f"agent_{i}", ["roslaunch", PKG, "agent.launch", f"id:={i}",
                                                   f"scenario:={scenario}", *extra])
                for host, ids in AGENTS_ON.items() for i in ids}


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
            self.assertTrue(hosts.start_watcher(f"/formation/agent_{victim}/state", kill[0], RUN_TIMEOUT),
                            f"the step watcher did not start:\n{hosts.log('watch')}")
        out = os.path.join(self.tmp, "out")
        run = hosts.start("A", "formation", ["rosrun", PKG, "run_formation.sh", f"scenario:={SCENARIO}",
                                             "agents:=false", "record:=true", f"output_dir:={out}", *extra])
        if kill:
            seen = hosts.watched_step(RUN_TIMEOUT + 10)
            self.assertIsNotNone(seen, f"the step watcher said nothing:\n{hosts.log('watch')}\n{hosts.log('formation')}")
            self.assertGreaterEqual(seen, kill[0], f"the run did not reach step {kill[0]}:\n{hosts.log('formation')}")
            self.assertLess(seen, int(self.scenario["steps"]), "the watcher saw the step only after the run")
            kill[1](agents, seen)
        # On a timeout the run is ended: the monitor writes why it was still waiting.
        result, late = vf_netns.finish_run(run, os.path.join(out, SCENARIO + ".result.yaml"), RUN_TIMEOUT)
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
        vf_netns.probe_main(sys.argv[2:])
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
