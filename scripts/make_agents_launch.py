#!/usr/bin/python3
"""Writes the launch file of a formation's agents: one include of agent.launch per agent.

formation.launch runs it at parse time (as a <param command>) and then includes the file it
wrote, so that any scenario starts one real roslaunch node per agent without a launch file per
scenario. The scenario is checked by the package's one loader (scenario_info); the arguments
here. Prints the path it wrote (the parameter's value). On bad input: one line on stderr,
exit status 2.

usage: make_agents_launch.py --scenario FILE --out FILE [--rate R] [--order forward|reverse]
                             [--stagger SECONDS] [--respawn true|false] [--manager NAME]
--manager loads every agent as a nodelet into that manager (agent.launch manager:=NAME).
"""
import argparse
import math
import os
import subprocess
import sys
from xml.sax.saxutils import quoteattr


def fail(message):
    print(f"make_agents_launch: error: {message}", file=sys.stderr, flush=True)
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


def agent_count(scenario, rate):
    info = subprocess.run(["rosrun", "variational_formation", "scenario_info", "--scenario", scenario,
                           "--real-time-factor", rate], capture_output=True, text=True)
    if info.returncode != 0:
        lines = info.stderr.strip().splitlines() or ["scenario_info failed"]
        fail(lines[-1].replace("scenario_info: error: ", ""))
    return int(info.stdout.split()[1])


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--scenario", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--rate", type=non_negative("rate"), default="0")
    parser.add_argument("--order", choices=("forward", "reverse"), default="forward")
    parser.add_argument("--stagger", type=non_negative("stagger"), default="0")
    parser.add_argument("--respawn", type=boolean("respawn"), default="true")
    parser.add_argument("--manager", default="")
    parser.error = lambda message: fail(message.replace("argument --", ""))
    args = parser.parse_args()
    count = agent_count(args.scenario, args.rate)
    ids = list(range(count))
    if args.order == "reverse":
        ids.reverse()
    lines = ["<launch>",
             f"  <!-- written by make_agents_launch.py for {args.scenario}: {count} agents -->"]
    for position, i in enumerate(ids):
        delay = position * float(args.stagger)
        prefix = f"bash -c 'sleep {delay:g}; exec \"$0\" \"$@\"'" if delay > 0 else ""
        lines.append('  <include file="$(find variational_formation)/launch/agent.launch">')
        for name, value in (("id", str(i)), ("scenario", args.scenario), ("rate", args.rate),
                            ("respawn", args.respawn), ("launch_prefix", prefix)) + \
                ((("manager", args.manager),) if args.manager else ()):
            lines.append(f"    <arg name={quoteattr(name)} value={quoteattr(value)}/>")
        lines.append("  </include>")
    lines.append("</launch>")
    try:
        os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
        with open(args.out, "w") as f:
            f.write("\n".join(lines) + "\n")
    except OSError as e:
        fail(f"--out: cannot write {args.out}: {e.strerror}")
    print(args.out)


if __name__ == "__main__":
    main()
