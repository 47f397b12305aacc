#!/usr/bin/python3
"""Sharded managers (catkin_make run_tests, as root): a 60-agent formation (test/ros/ring60.yaml,
a ring with chords, 600 steps) split over three hosts, a third of it in one nodelet manager on
each, and the master, the monitor and the recorder on a fourth. The hosts are network namespaces
on a bridge (vf_netns.py, shared with multihost_test.py), at 10.213.51.1-4, each with its own
ROS_IP / ROS_HOSTNAME:

- host A (10.213.51.1): roscore and `run_formation.sh agents:=false record:=true
  agent_manager:="manager_b manager_c manager_d"` (the monitor and the recorder);
- hosts B, C, D (10.213.51.2-4): agents 0-19, 20-39, 40-59, each third in one respawning
  agent_manager (formation/manager_b, _c, _d), loaded by the launch file that `make_agents_launch.py
  --nodelet true --ids ... --manager-name ... --agent-manager ...` writes on that host.

Case `run`: the run succeeds; the bag is complete and equals simulate bit for bit (every state,
status, marker and tf of every step, once). Where each agent ran: the master's only publisher of
agent_<i>/state is its host's manager, whose XML-RPC URI is at that host's address and whose
process (its pid, asked of the node) is the agent_manager under that host's roslaunch, in that
host's network namespace; its ~agents is its third. The monitor and the recorder receive the
states batched, each manager's `states` over a live TCP connection from that manager (its URI)
at its host's address, and no agent's own topic: sampled on host A while the recorder is up (it
ends with the run), and for the monitor again after the run.

Case `kill`: the managers pace the run at rate 0.5 (6 s). At a seeded random step (watched on
host A on the victim's first agent) one manager process, drawn by the seed, gets a real SIGKILL
(found by pid under its host's roslaunch and checked to be in that host's namespace). Its
roslaunch respawns it (a new pid, same host), it reloads its 20 agents, they recover, and the run
still succeeds with a bag equal to simulate bit for bit; the placement checks hold again after,
with the new process, and the monitor takes the victim's batches from it. The other managers
kept their processes.
VF_SHARDED_SEED=N draws the same manager and step.

Each case removes its namespaces (with their veths and bridge) and every process it started,
also on failure, and checks that none is left. Master ports 11760 (run) and 11761 (kill).

  sharded_test.py [--gtest_output=xml:PATH]
"""
import os
import random
import shutil
import signal
import sys
import tempfile
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vf_netns  # noqa: E402
import vf_rostest  # noqa: E402

PKG = vf_rostest.PKG
SCENARIO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "ring60.yaml")
NAME = "ring60"
NS = "/formation"
SUBNET = "10.213.51"
HOST_NUMBER = {"A": 1, "B": 2, "C": 3, "D": 4}
SHARDS = {"B": range(0, 20), "C": range(20, 40), "D": range(40, 60)}
MANAGER = {host: f"manager_{host.lower()}" for host in SHARDS}
PORT_RUN, PORT_KILL = 11760, 11761
RUN_TIMEOUT = 60.0  # seconds from formation.launch's start to the result (a run takes 2-8 s)
KILL_RATE = "0.5"   # real-time factor of the kill case: 600 steps of h = 5 ms take 6 s


def host_of(agent):
    return next(h for h, ids in SHARDS.items() if agent in ids)


class Hosts(vf_netns.Hosts):
    """Four hosts A, B, C, D (vf_netns.Hosts): namespaces vfsh<port>_a.._d on the bridge of
    vfsh<port>_br, at 10.213.51.1-4; ROS_HOME in the test's directory."""

    def __init__(self, port, workdir):
        super().__init__(port, workdir, SUBNET, HOST_NUMBER, prefix="vfsh", label="sharded")

    def env(self, host):
        return dict(super().env(host), ROS_HOME=os.path.join(self.workdir, "ros_home"))

    def start_managers(self, rate):
        """On each of B, C, D: its launch file, written there by make_agents_launch.py, then
        `roslaunch` of it: one respawning agent_manager with its third of the agents."""
        launches = {}
        for host, ids in SHARDS.items():
            path = os.path.join(self.workdir, f"shard_{host.lower()}.launch")
            made = self.run(host, ["rosrun", PKG, "make_agents_launch.py", "--scenario", SCENARIO, "--nodelet", "true",
                                   "--ids", f"{ids[0]}-{ids[-1]}", "--manager-name", MANAGER[host],
                                   "--agent-manager", " ".join(MANAGER.values()), "--rate", rate, "--out", path],
                            timeout=60)
            if made.returncode != 0:
                raise AssertionError(f"make_agents_launch.py on host {host}: {made.stderr}")
            launches[host] = self.start(host, f"shard_{host.lower()}", ["roslaunch", path])
        return launches


@vf_rostest.reported_setup
class Sharded(unittest.TestCase, vf_rostest.RunChecks):
    @classmethod
    def setUpClass(cls):
        cls.scenario = vf_rostest.load_scenario(SCENARIO)
        cls.expected = vf_rostest.simulate(SCENARIO)

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="vf_sharded_")
        self.started = time.monotonic()

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)
        vf_netns.report(f"sharded: {self.id().split('.')[-1]} took {time.monotonic() - self.started:.1f} s")

    # --- where each agent runs --------------------------------------------------------------

    def manager_pid(self, hosts, launches, host):
        """The agent_manager process under `host`'s roslaunch (None: none, or several)."""
        pids = [p for p in vf_netns.descendants(launches[host].pid)
                if vf_netns.executable_of(p).endswith("/agent_manager")]
        return pids[0] if len(pids) == 1 else None

    def placement_problems(self, hosts, launches):
        """What is wrong with: agent i's state published by its host's manager only, that manager
        at its host's address, its process the agent_manager under that host's roslaunch and in
        that host's namespace, its ~agents its third. Also returns the managers' graph entries."""
        n = self.scenario["n"]
        names = [f"{NS}/agent_{i}/state" for i in range(n)] + [f"param:{NS}/{m}/agents" for m in MANAGER.values()]
        found = hosts.probe("publishers", *names, timeout=60.0)
        problems = []
        for i in range(n):
            expected = [f"{NS}/{MANAGER[host_of(i)]}"]
            if found[f"{NS}/agent_{i}/state"] != expected:
                problems.append(f"agent_{i}/state is published by {found[f'{NS}/agent_{i}/state']}, not {expected}")
        for host, ids in SHARDS.items():
            agents = found[f"param:{NS}/{MANAGER[host]}/agents"]
            if str(agents).split() != [str(i) for i in ids]:
                problems.append(f"{MANAGER[host]}/agents is {agents!r}, not agents {ids[0]}-{ids[-1]}")
        if problems:
            return problems, {}
        graph = hosts.probe("graph", *[f"{NS}/{m}" for m in MANAGER.values()], timeout=60.0)
        for host in SHARDS:
            info = graph[f"{NS}/{MANAGER[host]}"]
            if not info["uri"].startswith(f"http://{hosts.address(host)}:"):
                problems.append(f"{MANAGER[host]} is at {info['uri']}, not on host {host} ({hosts.address(host)})")
            local = self.manager_pid(hosts, launches, host)
            if info["pid"] != local:
                problems.append(f"{MANAGER[host]}'s pid {info['pid']} is not the agent_manager under host {host}'s "
                                f"roslaunch ({local})")
            if hosts.host_of_pid(info["pid"]) != host:
                problems.append(f"{MANAGER[host]} (pid {info['pid']}) runs in the namespace of host "
                                f"{hosts.host_of_pid(info['pid'])}, not {host}")
        return problems, graph

    def check_placement(self, hosts, launches, timeout=60.0):
        """Polls until every agent is up where it belongs (the managers load them at start);
        returns the managers' graph entries (uri, pid, bus) by host."""
        end = time.time() + timeout
        while True:
            problems, graph = self.placement_problems(hosts, launches)
            if not problems or time.time() > end:
                break
            time.sleep(0.5)
        self.assertEqual(problems, [], "\n".join(hosts.log(f"shard_{h.lower()}", 1500) for h in SHARDS))
        return {host: graph[f"{NS}/{MANAGER[host]}"] for host in SHARDS}

    def check_batched(self, hosts, graph, managers, when):
        """Each node of `graph` (the monitor, the recorder: host A) takes every agent's states
        out of the managers' batches: a live inbound connection on each manager's `states` from
        that manager (its URI: one of the graph entries in `managers`, by host) at its host's
        address, and none on an agent's own topic."""
        for node, info in sorted(graph.items()):
            self.assertTrue(info["uri"].startswith(f"http://{hosts.address('A')}:"), f"{node} at {info['uri']}")
            inbound = [c for c in info["bus"] if c[2] == "i" and c[5]]
            for host, entries in managers.items():
                topic = f"{NS}/{MANAGER[host]}/states"
                links = [c for c in inbound if c[4] == topic]
                self.assertTrue(links, f"{when}: {node} receives nothing on {topic}: {inbound}")
                for c in links:
                    manager = next((m for m in entries if m["uri"] == c[1]), None)
                    self.assertIsNotNone(manager, f"{when}: {node}'s {topic} comes from {c[1]}, not from "
                                                  f"{[m['uri'] for m in entries]}")
                    self.assertIn(f"[{hosts.address(host)}:", c[6], f"{when}: {node}'s {topic}: {c[6]}")
                    vf_netns.report(f"sharded: {when}: {node} receives agents {SHARDS[host][0]}-{SHARDS[host][-1]} "
                                    f"batched on {topic} from {c[1]} (pid {manager['pid']}, host {host})")
            own = sorted({c[4] for c in inbound if c[4].startswith(f"{NS}/agent_") and c[4].endswith("/state")})
            self.assertEqual(own, [], f"{when}: {node} subscribes to agents' own topics")

    # --- the run ---------------------------------------------------------------------------------

    def run_formation(self, hosts, kill_seed=None):
        """Master, managers (their agents wait for the monitor), then the monitor and recorder on
        A. With kill_seed, one manager is SIGKILLed at a seeded step. Returns the kill's record
        ({} without)."""
        hosts.start_master()
        launches = hosts.start_managers(KILL_RATE if kill_seed is not None else "0")
        before = self.check_placement(hosts, launches)
        killed = {}
        if kill_seed is not None:
            rng = random.Random(kill_seed)
            victim = rng.choice(sorted(SHARDS))
            steps = int(self.scenario["steps"])
            step = rng.randint(steps // 10, 2 * steps // 3)
            killed.update(host=victim, drawn=step)
            # The watcher subscribes before the run starts, so it sees the step when it comes.
            self.assertTrue(hosts.start_watcher(f"{NS}/agent_{SHARDS[victim][0]}/state", step, RUN_TIMEOUT),
                            f"the step watcher did not start:\n{hosts.log('watch')}")
        # The recorder is up only during the run: its connections (and the monitor's) are
        # sampled then, by a probe on A started before them.
        batches = [f"{NS}/{m}/states" for m in MANAGER.values()]
        hosts.start_connections([f"{NS}/monitor", f"{NS}/recorder"], batches, RUN_TIMEOUT)
        out = os.path.join(self.tmp, "out")
        run = hosts.start("A", "formation", ["rosrun", PKG, "run_formation.sh", f"scenario:={SCENARIO}",
                                             "agents:=false", "record:=true", f"output_dir:={out}",
                                             f"agent_manager:={' '.join(MANAGER.values())}", "end_with_run:=false"])
        if kill_seed is not None:
            seen = hosts.watched_step(RUN_TIMEOUT)
            self.assertIsNotNone(seen, f"the step watcher said nothing:\n{hosts.log('watch')}\n{hosts.log('formation')}")
            self.assertGreaterEqual(seen, step, f"the run did not reach step {step}:\n{hosts.log('formation')}")
            pid = self.manager_pid(hosts, launches, victim)
            self.assertEqual(pid, before[victim]["pid"], f"{MANAGER[victim]} is not the process it was")
            self.assertEqual(hosts.host_of_pid(pid), victim)
            os.kill(pid, signal.SIGKILL)
            result = vf_rostest.wait_for_result(os.path.join(out, NAME + ".result.yaml"), 0)
            self.assertEqual(result.get("result", "running"), "running", "the run was over before the kill")
            self.assertLess(seen, int(self.scenario["steps"]), "the watcher saw the step only after the run")
            killed.update(pid=pid, step=seen, at=time.monotonic())
            vf_netns.report(f"sharded: seed {kill_seed}: SIGKILL to {NS}/{MANAGER[victim]} (pid {pid}) on host "
                            f"{victim} ({hosts.address(victim)}), agents {SHARDS[victim][0]}-{SHARDS[victim][-1]}, "
                            f"once agent_{SHARDS[victim][0]} had published step {seen} (drawn: {step}); "
                            f"VF_SHARDED_SEED={kill_seed} draws the same")
        result = vf_rostest.wait_for_result(os.path.join(out, NAME + ".result.yaml"), RUN_TIMEOUT)
        shard_logs = "".join(f"\nhost {h}'s roslaunch:\n{hosts.log(f'shard_{h.lower()}', 1500)}" for h in SHARDS)
        self.assertEqual(result.get("result"), "succeeded",
                         f"result file: {result}\n{hosts.log('formation')}{shard_logs}")
        if killed:
            vf_netns.report(f"sharded: the run ended {time.monotonic() - killed['at']:.1f} s after the kill")
        during = hosts.answer("connections", RUN_TIMEOUT)
        self.assertIsNotNone(during, f"the connection probe said nothing:\n{hosts.log('connections')}")
        for node in (f"{NS}/monitor", f"{NS}/recorder"):
            self.assertTrue(during.get(node, {}).get("complete"),
                            f"{node} never had a connection on each of {batches}: {during.get(node)}")
        # Where the agents ran, at the end (after a kill: the respawned manager, on the same host),
        # and the monitor (still up) takes their batches from there. The sample during the run is
        # taken as soon as it has every batch, before the run starts; should it come after the
        # kill, the victim's batches came from its new process.
        after = self.check_placement(hosts, launches)
        self.check_batched(hosts, during, {h: [before[h], after[h]] for h in SHARDS}, "during the run")
        self.check_batched(hosts, hosts.probe("graph", f"{NS}/monitor", timeout=30.0),
                           {h: [after[h]] for h in SHARDS}, "after the run")
        if killed:
            victim = killed["host"]
            self.assertNotEqual(after[victim]["pid"], killed["pid"], f"{MANAGER[victim]} was not respawned")
            self.assertIn(f"[formation/{MANAGER[victim]}-1] restarting process", hosts.log(f"shard_{victim.lower()}", 0))
            for host in SHARDS:
                if host != victim:
                    self.assertEqual(after[host]["pid"], before[host]["pid"], f"{MANAGER[host]} restarted")
        # end_with_run:=false: the nodes stay up (the checks above asked them); end the launch,
        # and run_formation.sh then reads the result file.
        vf_netns.kill_group(run)
        self.assertEqual(run.returncode, 0, hosts.log("formation"))
        vf_netns.kill_group(*launches.values())
        for host, proc in launches.items():
            self.assertIsNotNone(proc.poll(), f"host {host}'s roslaunch did not end:\n{hosts.log(f'shard_{host.lower()}')}")
        for host in SHARDS:
            vf_netns.report(f"sharded: agents {SHARDS[host][0]}-{SHARDS[host][-1]} ran in {NS}/{MANAGER[host]} "
                            f"(pid {after[host]['pid']}) at {after[host]['uri']}, host {host}")
        rec = vf_rostest.Recording(os.path.join(out, NAME + ".bag"))
        self.check_recording(rec, self.scenario, self.expected)
        return killed

    def run_case(self, port, kill_seed=None):
        hosts = Hosts(port, self.tmp)
        try:
            hosts.up()
            killed = self.run_formation(hosts, kill_seed)
        finally:
            hosts.down()
        self.assertEqual(hosts.leftovers(), [], "network namespaces left behind")
        self.assertEqual([p.args for p in hosts.procs if p.poll() is None], [], "processes left behind")
        return killed

    def test_run_thirds_on_three_hosts_equals_simulate(self):
        self.run_case(PORT_RUN)

    def test_manager_killed_on_one_host_respawns_and_the_run_equals_simulate(self):
        seed = int(os.environ.get("VF_SHARDED_SEED", time.time_ns() % 1_000_000))
        killed = self.run_case(PORT_KILL, seed)
        self.assertIn("pid", killed, "no manager was killed")


if __name__ == "__main__":
    import rosunit
    rosunit.unitrun(PKG, "sharded", Sharded)
