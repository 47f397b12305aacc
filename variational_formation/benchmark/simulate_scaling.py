#!/usr/bin/python3
"""simulate's cost per agent-step as the formation grows (issue 34's target: within 1.3x from 100
to 10,000 agents).

  simulate_scaling.py [AGENTS ...] [--agent-steps A | --steps S] [--simulate PATH]
      (default 100 1000 10000, 2,000,000 agent-steps per count)

For each count: a ring with chords (+-1, +-2), spacing 1 m, start perturbed by up to 0.05 m per
coordinate (seed 1), kappa 2, h = 0.005 s, the layout of `make_scenario --shape ring` (which
stops at 2000 agents); then `simulate --metrics`, whose CPU time (user + system, from the child's
rusage) is split into the load (`simulate --steps 1`) and the steps (the rest). Every count runs
about the same agent-steps, max(200, A / agents) steps (20,000 at 100 agents, 200 at 10,000), so
that each measures seconds of stepping; --steps S gives every count S steps instead. (Until issue
34's last round every count ran 200 steps: 0.02 s of CPU at 100 agents, whose figure then moved
from 0.77 to 1.10 us per agent-step between runs.) Prints a Markdown table: load s, the steps' CPU
s (and how many steps), microseconds per agent-step, and the ratio of that to the first count's.
"""
import argparse
import math
import os
import random
import resource
import subprocess
import sys
import tempfile


def ring_yaml(n, steps):
    """The scenario text of an n-agent ring with chords to the second neighbour."""
    radius = 1.0 / (2.0 * math.sin(math.pi / n))  # neighbours 1 m apart
    rng = random.Random(1)
    lines = [f"name: ring{n}", "dimension: 2", "kappa: 2", "time_step: 0.005", f"steps: {steps}", "agents:"]
    for i in range(n):
        a = 2.0 * math.pi * i / n
        x, y = radius * math.cos(a), radius * math.sin(a)
        px, py = x + rng.uniform(-0.05, 0.05), y + rng.uniform(-0.05, 0.05)
        lines.append(f"  - {{id: {i}, initial_position: [{px!r}, {py!r}], initial_velocity: [0, 0], "
                     f"desired_position: [{x!r}, {y!r}]}}")
    edges = [f"[{i}, {(i + k) % n}]" for i in range(n) for k in (1, 2)]
    lines.append("edges: [" + ", ".join(edges) + "]")
    return "\n".join(lines) + "\n"


def cpu_seconds(command):
    """CPU time of a child process run to its end (user + system), in seconds."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    result = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if result.returncode != 0:
        sys.exit(f"simulate_scaling: {' '.join(command)} failed: {result.stderr.strip()}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("agents", nargs="*", type=int, default=[100, 1000, 10000])
    parser.add_argument("--agent-steps", type=int, default=2000000)
    parser.add_argument("--steps", type=int, default=None)
    parser.add_argument("--simulate", default=os.path.join(os.environ.get("VF_WS", os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "..", ".ws")), "devel", "lib", "variational_formation", "simulate"))
    args = parser.parse_args()
    if any(n < 5 for n in args.agents) or (args.steps is not None and args.steps < 2) or args.agent_steps < 1:
        sys.exit("simulate_scaling: needs agent counts >= 5, --steps >= 2 and --agent-steps >= 1")
    rows, first = [], None
    with tempfile.TemporaryDirectory() as tmp:
        for n in args.agents:
            steps = args.steps if args.steps is not None else max(200, args.agent_steps // n)
            scenario = os.path.join(tmp, f"ring{n}.yaml")
            with open(scenario, "w") as f:
                f.write(ring_yaml(n, steps))
            base = [args.simulate, "--scenario", scenario, "--out", os.devnull, "--metrics", os.devnull]
            load = cpu_seconds(base + ["--steps", "1"])
            total = cpu_seconds(base)
            stepping = max(0.0, total - load)
            per = 1e6 * stepping / (n * (steps - 1))
            first = first or per
            rows.append(f"| {n} | {load:.2f} | {stepping:.2f} ({steps} steps) | {per:.2f} | {per / first:.2f} |")
    print(f"| agents | load, CPU s | steps, CPU s | µs per agent-step | ratio to {args.agents[0]} |")
    print("| --- | --- | --- | --- | --- |")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
