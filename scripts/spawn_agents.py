#!/usr/bin/python3
"""Starts one agent node (its own process, /formation/agent_<id>) per agent of a scenario.

Used by launch/formation.launch, so that any scenario runs without per-scenario launch files.
The scenario is checked by the package's one loader (scenario_info). The spawner exits with
the first non-zero status of an agent (stopping the others), or 0 once all have finished; with
--linger it stays after a successful run until it is stopped, so that (as a required node) its
exit always means a failure, which ends the launch.

usage: spawn_agents.py --scenario FILE [--rate R] [--extra-subscribers N] [--tf-subscribers N]
                       [--order forward|reverse] [--stagger SECONDS] [--linger]
"""
import argparse
import signal
import subprocess
import sys
import time


def fail(message, status=2):
    print(f"spawn_agents: error: {message}", file=sys.stderr, flush=True)
    sys.exit(status)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--scenario", required=True)
    parser.add_argument("--rate", type=float, default=0.0)
    parser.add_argument("--extra-subscribers", type=int, default=1)
    parser.add_argument("--tf-subscribers", type=int, default=0)
    parser.add_argument("--order", choices=("forward", "reverse"), default="forward")
    parser.add_argument("--stagger", type=float, default=0.0)
    parser.add_argument("--linger", action="store_true")
    parser.error = fail  # one line, status 2
    args, _ = parser.parse_known_args()  # roslaunch appends __name:= and __log:=
    if not args.rate >= 0 or not args.stagger >= 0:  # also rejects nan
        fail(f"--rate and --stagger must be >= 0, got {args.rate} and {args.stagger}")
    info = subprocess.run(["rosrun", "variational_formation", "scenario_info", "--scenario", args.scenario],
                          capture_output=True, text=True)
    if info.returncode != 0:
        fail((info.stderr.strip().splitlines() or ["scenario_info failed"])[-1]
             .replace("scenario_info: error: ", ""), info.returncode)
    count = int(info.stdout.split()[1])
    ids = list(range(count))
    if args.order == "reverse":
        ids.reverse()
    children = {}
    stopping = False

    def stop(*_):
        nonlocal stopping
        stopping = True
        for p in children.values():
            if p.poll() is None:
                p.send_signal(signal.SIGINT)

    signal.signal(signal.SIGINT, stop)
    signal.signal(signal.SIGTERM, stop)
    for k, i in enumerate(ids):
        if stopping:
            break
        if k > 0 and args.stagger > 0:
            time.sleep(args.stagger)
        children[i] = subprocess.Popen([
            "rosrun", "variational_formation", "agent", f"__name:=agent_{i}", "__ns:=/formation",
            f"_id:={i}", f"_scenario:={args.scenario}", f"_real_time_factor:={args.rate}",
            f"_extra_subscribers:={args.extra_subscribers}", f"_tf_subscribers:={args.tf_subscribers}"])
    status = 0
    while children:
        for i, p in list(children.items()):
            code = p.poll()
            if code is None:
                continue
            del children[i]
            if code != 0 and status == 0 and not stopping:
                print(f"spawn_agents: agent_{i} exited with status {code}", file=sys.stderr, flush=True)
                status = code
                stop()
        time.sleep(0.05)
    while args.linger and status == 0 and not stopping:
        signal.pause()  # until roslaunch ends the run
    sys.exit(status)


if __name__ == "__main__":
    main()
