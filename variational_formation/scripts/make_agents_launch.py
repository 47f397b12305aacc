#!/usr/bin/python3
"""Writes the launch file of a formation's agents: one include of agent.launch per agent.

formation.launch runs it at parse time (as a <param command>) and then includes the file it
wrote, so that any scenario starts one real roslaunch node per agent without a launch file per
scenario. The scenario is checked by the package's one loader (scenario_info); the arguments
here. Prints the path it wrote (the parameter's value). On bad input: one line on stderr,
exit status 2.

usage: make_agents_launch.py --scenario FILE --out FILE [--rate R] [--order forward|reverse]
                             [--stagger SECONDS] [--respawn true|false] [--nodelet true|false [--nodelet-threads N (0: auto)]]
                             [--mode lockstep|timed [--delay S] [--jitter S] [--loss P] [--max-age S]
                              [--seed N] [--respawn-delay S] [--robot true|false [--lag S] [--noise M]
                               [--kinematics holonomic|unicycle] [--feedback integrated|odometry]
                               [--hand-offset M] [--heading-seed N] [--heading-noise RAD]
                               [--world kinematic|mujoco [--physics-step S] [--friction F]]
                               [--body-radius M] [--result-file PATH]]]
                             [--ids LIST] [--manager-name NAME] [--agent-manager NAMES] [--in-launch]
With --robot true (timed mode), each agent also gets a simulated robot, robot_sim, in
formation/robot_<id> (odom and cmd_vel there), started at the scenario's initial position (a
unicycle's hand point there, at the scenario's initial_heading or one drawn from --heading-seed).
Every robot_sim counts body contacts (bodies closer than 2 --body-radius, default the TurtleBot3
Burger's 0.105 m); robot 0 counts every pair and adds `contacts:` to --result-file at the end.
With --world mujoco the robots are not robot_sim nodes but bodies of one MuJoCo world, which
robots.launch starts (mujoco_world); the agents' robot lag is then the world's measured step
response (world_step_response, with the world's --physics-step and --friction), not --lag.
With --nodelet true (lockstep mode), every agent is a nodelet of one manager, formation/manager
(the agent_manager node, which loads them itself; doc/distributed.md, "Nodelets"), instead of a
node of its own.
A formation spread over several machines (doc/distributed.md, "Sharded managers"): --ids 0-19
writes only those agents (ranges and ids separated by commas), --manager-name manager_b names
their manager formation/manager_b, and --agent-manager "manager_b manager_c manager_d" lists
every manager of the formation, whose caller ids the agents' neighbours' states may carry.
"""
import argparse
import math
import os
import re
import subprocess
import sys
from xml.sax.saxutils import quoteattr

import yaml


def fail(message):
    """One line on stderr and exit status 2. With --in-launch (formation.launch), the status is 0
    and --out is a launch file that ends roslaunch quietly with status 2 once included: a failed
    <param command> would make roslaunch add a multi-line dump of the command to the line."""
    print(f"make_agents_launch: error: {message}", file=sys.stderr, flush=True)
    argv = sys.argv[1:]
    if "--in-launch" in argv and "--out" in argv[:-1]:
        out = argv[argv.index("--out") + 1]
        try:
            with open(out, "w") as f:
                f.write("<launch>\n  <!-- make_agents_launch.py: bad input, said on stderr -->\n"
                        '  <arg name="bad_input" value="$(eval exit(2))"/>\n</launch>\n')
            print(out)
            sys.exit(0)
        except OSError:
            pass
    sys.exit(2)


def non_negative(flag):
    def parse(text):
        try:
            value = float(text)
        except ValueError:
            fail(f"{flag}: expected a number, got '{text}'")
        if not (value >= 0 and math.isfinite(value)):
            fail(f"{flag}: must be a finite number >= 0, got {text}")
        return text
    return parse


def boolean(flag):
    def parse(text):
        if text.lower() in ("true", "1"):
            return "true"
        if text.lower() in ("false", "0"):
            return "false"
        fail(f"{flag}: expected true or false, got '{text}'")
    return parse


def non_negative_int(flag):
    def parse(text):
        try:
            value = int(text)
        except ValueError:
            fail(f"{flag}: expected an integer, got '{text}'")
        if value < 0:
            fail(f"{flag}: must be >= 0, got {text}")
        return text
    return parse


def manager(args, ids):
    """The agents' nodelet manager, which loads every agent in `ids` (in that order) itself.
    Threads 0 means one (doc/distributed.md, "Threads")."""
    threads = args.nodelet_threads if int(args.nodelet_threads) > 0 else "1"
    lines = [f'  <node name={quoteattr(args.manager_name)} ns="formation" pkg="variational_formation" type="agent_manager"'
             ' clear_params="true"', f'        respawn={quoteattr(args.respawn)} output="screen">']
    # Managers on other machines: their agents' states, neighbours of these, carry their names.
    others = (("agent_manager", "str", args.agent_manager),) if args.agent_manager else ()
    for name, kind, value in (("agents", "str", " ".join(str(i) for i in ids)), ("scenario", "str", args.scenario),
                              ("real_time_factor", "double", args.rate), ("stagger", "double", args.stagger),
                              ("num_worker_threads", "int", threads)) + others:
        lines.append(f"    <param name={quoteattr(name)} type={quoteattr(kind)} value={quoteattr(value)}/>")
    lines.append("  </node>")
    return lines


def probability(flag):
    def parse(text):
        non_negative(flag)(text)
        if float(text) > 1:
            fail(f"{flag}: must be a probability in [0, 1], got {text}")
        return text
    return parse


def positive(flag):
    def parse(text):
        non_negative(flag)(text)
        if float(text) <= 0:
            fail(f"{flag}: must be > 0, got {text}")
        return text
    return parse


def seed(text):
    if not text.isdigit():
        fail(f"seed: must be an integer >= 0, got '{text}'")
    return int(text)


def id_list(text):
    """--ids: ids and ranges separated by commas ("0-19", "0-9,20,30-39"), in that order, each once."""
    ids = []
    for part in text.split(","):
        low, dash, high = part.strip().partition("-")
        if not low.isdigit() or (dash and not high.isdigit()):
            fail(f"ids: expected ids or ranges separated by commas (0-19,40), got '{text}'")
        span = range(int(low), int(high if dash else low) + 1)
        if not span:
            fail(f"ids: empty range '{part.strip()}'")
        ids += [i for i in span if i not in ids]
    return ids


def node_name(flag):
    def parse(text):
        if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", text):
            fail(f"{flag}: expected a node name (a letter, then letters, digits or _), got '{text}'")
        return text
    return parse


def agent_count(scenario, rate):
    info = subprocess.run(["rosrun", "variational_formation", "scenario_info", "--scenario", scenario,
                           "--real-time-factor", rate], capture_output=True, text=True)
    if info.returncode != 0:
        lines = info.stderr.strip().splitlines() or ["scenario_info failed"]
        fail(lines[-1].replace("scenario_info: error: ", ""))
    return int(info.stdout.split()[1])


def world_lag(args):
    """The lag of the MuJoCo world's robots: the time their speed takes to 63.2% of a step."""
    response = subprocess.run(["rosrun", "variational_formation", "world_step_response", "--kinematics", args.kinematics,
                               "--time_step", args.physics_step, "--friction", args.friction],
                              capture_output=True, text=True)
    if response.returncode != 0:
        lines = response.stderr.strip().splitlines() or ["world_step_response failed"]
        fail(lines[-1].replace("world_step_response: error: ", ""))
    return response.stdout.split()[1]


def timed_args(args, i, lag):
    if args.mode != "timed":
        return ()
    # One fault stream per agent: seed + id.
    return (("mode", "timed"), ("respawn_delay", args.respawn_delay), ("delay", args.delay),
            ("jitter", args.jitter), ("loss", args.loss),
            ("max_age", args.max_age), ("seed", str(args.seed + i)), ("robot", args.robot)) + (
                (("kinematics", args.kinematics), ("feedback", args.feedback), ("hand_offset", args.hand_offset),
                 ("robot_lag", lag)) if args.robot == "true" else ())


def robot_sim(args, i):
    """A simulated robot for agent i, at the scenario's initial position (the loader checked it)."""
    with open(args.scenario) as f:
        agents = yaml.safe_load(f)["agents"]
    agent = next(a for a in agents if int(a["id"]) == i)
    start = ", ".join(repr(float(x)) for x in agent["initial_position"])
    unicycle = []
    if args.kinematics == "unicycle":
        # The scenario's initial_heading if it has one, else robot_sim draws it from heading_seed.
        heading = agent.get("initial_heading")
        unicycle = [f'    <param name="kinematics" type="str" value="unicycle"/>',
                    f'    <param name="hand_offset" type="double" value="{args.hand_offset}"/>',
                    f'    <param name="heading_seed" type="int" value="{args.heading_seed}"/>',
                    f'    <param name="heading_noise" type="double" value="{args.heading_noise}"/>'] + (
            [f'    <param name="initial_heading" type="double" value="{float(heading)!r}"/>'] if heading is not None else [])
    return [f'  <node name="robot_sim" ns="formation/robot_{i}" pkg="variational_formation" type="robot_sim" '
            'output="screen">',
            f'    <param name="id" type="int" value="{i}"/>',
            f'    <rosparam param="initial_position">[{start}]</rosparam>',
            f'    <param name="lag" type="double" value="{args.lag}"/>',
            f'    <param name="odometry_noise" type="double" value="{args.noise}"/>',
            f'    <param name="seed" type="int" value="{args.seed + i}"/>',
            # Body contacts (doc/robots.md "Contacts"): robot 0 counts every pair into the result file.
            f'    <param name="robots" type="int" value="{len(agents)}"/>',
            f'    <param name="body_radius" type="double" value="{args.body_radius}"/>'] + (
        [f'    <param name="result_file" type="str" value={quoteattr(args.result_file)}/>']
        if i == 0 and args.result_file else []) + unicycle + ["  </node>"]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--scenario", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--rate", type=non_negative("rate"), default="0")
    parser.add_argument("--order", choices=("forward", "reverse"), default="forward")
    parser.add_argument("--stagger", type=non_negative("stagger"), default="0")
    parser.add_argument("--respawn", type=boolean("respawn"), default="true")
    # Timed mode (doc/robots.md): passed to the agents only then, so lockstep files stay as they were.
    parser.add_argument("--mode", choices=("lockstep", "timed"), default="lockstep")
    parser.add_argument("--delay", type=non_negative("delay"), default="0")
    parser.add_argument("--jitter", type=non_negative("jitter"), default="0")
    parser.add_argument("--loss", type=probability("loss"), default="0")
    parser.add_argument("--max-age", type=positive("max_age"), default="0.5")
    parser.add_argument("--seed", type=seed, default=0)
    parser.add_argument("--robot", type=boolean("robot"), default="false")
    parser.add_argument("--respawn-delay", type=non_negative("respawn_delay"), default="0")
    parser.add_argument("--lag", type=non_negative("lag"), default="0.1")
    parser.add_argument("--noise", type=non_negative("noise"), default="0.01")
    parser.add_argument("--kinematics", choices=("holonomic", "unicycle"), default="holonomic")
    parser.add_argument("--feedback", choices=("integrated", "odometry"), default="integrated")
    parser.add_argument("--hand-offset", type=positive("hand_offset"), default="0.1")
    parser.add_argument("--heading-seed", type=seed, default=0)
    parser.add_argument("--heading-noise", type=non_negative("heading_noise"), default="0.01")
    parser.add_argument("--world", choices=("kinematic", "mujoco"), default="kinematic")
    parser.add_argument("--body-radius", type=positive("body_radius"), default="0.105")
    parser.add_argument("--result-file", default="")
    parser.add_argument("--physics-step", type=positive("physics_step"), default="0.002")
    parser.add_argument("--friction", type=positive("friction"), default="1")
    parser.add_argument("--nodelet", type=boolean("nodelet"), default="false")
    parser.add_argument("--nodelet-threads", type=non_negative_int("nodelet_threads"), default="0")
    parser.add_argument("--ids", type=id_list, default=None,
                        help="only these agents, ids and ranges separated by commas (0-19,40); default: all")
    parser.add_argument("--manager-name", type=node_name("manager_name"), default="manager",
                        help="with --nodelet true: the manager's name in formation/ (default manager), e.g. one per machine")
    parser.add_argument("--agent-manager", default="",
                        help="with --nodelet true: the formation's managers (names separated by spaces) whose caller id "
                             "a neighbour's state may carry: every manager of a formation spread over machines")
    parser.add_argument("--in-launch", action="store_true")
    parser.error = lambda message: fail(message.replace("argument --", ""))
    args = parser.parse_args()
    if args.robot == "true" and args.mode != "timed":
        fail("robot: robots need mode timed")
    if args.nodelet == "true" and args.mode != "lockstep":
        fail("nodelet: only lockstep agents are nodelets; run timed agents as nodes (nodelet:=false)")
    if args.mode == "timed" and float(args.rate) <= 0:
        fail(f"rate: must be > 0 in timed mode (the tick period is h / rate), got {args.rate}")
    if args.world == "mujoco" and args.robot != "true":
        fail("world: a MuJoCo world holds robots: it needs robot true")
    if args.nodelet != "true" and (args.manager_name != "manager" or args.agent_manager):
        fail("manager_name, agent_manager: only with nodelet true")
    count = agent_count(args.scenario, args.rate)
    ids = list(range(count))
    if args.ids is not None:
        beyond = [i for i in args.ids if i >= count]
        if beyond:
            fail(f"ids: agent {beyond[0]} does not exist (the scenario has {count} agents)")
        ids = args.ids
    if args.order == "reverse":
        ids.reverse()
    lines = ["<launch>",
             f"  <!-- written by make_agents_launch.py for {args.scenario}: {count} agents -->"]
    if args.ids is not None:
        lines.append(f"  <!-- of them {len(ids)}: {' '.join(str(i) for i in ids)} -->")
    if args.nodelet == "true":
        lines += manager(args, ids)
        ids = []
    lag = args.lag
    if args.world == "mujoco":
        lag = world_lag(args)
        lines.append(f"  <!-- the MuJoCo world's robots (robots.launch starts it): measured lag {lag} s -->")
    for position, i in enumerate(ids):
        delay = position * float(args.stagger)
        prefix = f"bash -c 'sleep {delay:g}; exec \"$0\" \"$@\"'" if delay > 0 else ""
        lines.append('  <include file="$(find variational_formation)/launch/agent.launch">')
        for name, value in (("id", str(i)), ("scenario", args.scenario), ("rate", args.rate),
                            ("respawn", args.respawn), ("launch_prefix", prefix)) + timed_args(args, i, lag):
            lines.append(f"    <arg name={quoteattr(name)} value={quoteattr(value)}/>")
        lines.append("  </include>")
        if args.robot == "true" and args.world == "kinematic":
            lines += robot_sim(args, i)
    lines.append("</launch>")
    try:
        os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
        # Written beside and renamed over: a launch reading the same file meanwhile sees it whole.
        partial = f"{args.out}.{os.getpid()}.partial"
        with open(partial, "w") as f:
            f.write("\n".join(lines) + "\n")
        os.replace(partial, args.out)
    except OSError as e:
        fail(f"--out: cannot write {args.out}: {e.strerror}")
    print(args.out)


if __name__ == "__main__":
    main()
