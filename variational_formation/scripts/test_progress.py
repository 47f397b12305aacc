"""Prints the test run as it goes (scripts/test.sh runs it beside `catkin_make run_tests -j1`):
one line per result file as it appears in the test results folder (result, seconds since the
previous one finished, name), and, once the run process has ended, the ten slowest.
A rostest writes its node's results (rosunit-*.xml) and then its wrapper (rostest-*.xml): the
pair is one line, under the wrapper's name. Tests run one at a time, so the seconds between two
result files are the later test's (with make's few tenths of a second).

usage: /usr/bin/python3 scripts/test_progress.py RESULTS_DIR PID"""
import os
import sys
import time
import xml.etree.ElementTree as ElementTree


def outcome(path):
    """'ok', 'FAILED' (failures, errors or no test at all), or None while the file is incomplete."""
    try:
        root = ElementTree.parse(path).getroot()
    except (ElementTree.ParseError, OSError):
        return None
    suites = [root] if root.tag == "testsuite" else list(root.iter("testsuite"))
    tests = sum(int(s.get("tests", 0)) for s in suites)
    bad = sum(int(s.get("failures", 0)) + int(s.get("errors", 0)) for s in suites)
    return "ok" if tests > 0 and bad == 0 else "FAILED"


def result_files(folder):
    for parent, _, names in os.walk(folder):
        for name in names:
            if name.endswith(".xml"):
                yield os.path.join(parent, name)


def alive(pid):
    try:
        os.kill(pid, 0)
        return True
    except ProcessLookupError:
        return False
    except PermissionError:
        return True


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    folder, pid = sys.argv[1], int(sys.argv[2])
    seen, timings, last = set(), [], time.monotonic()
    while True:
        running = alive(pid)
        for path in sorted(set(result_files(folder)) - seen, key=lambda p: os.path.getmtime(p)):
            result = outcome(path)
            if result is None and running:
                continue  # still being written
            seen.add(path)
            name = os.path.basename(path)[:-len(".xml")]
            if name.startswith("rosunit-"):
                continue  # its rostest wrapper follows
            now = time.monotonic()
            seconds, last = now - last, now
            timings.append((seconds, name))
            print(f"{result or 'FAILED':6} {seconds:7.1f} s  {name}", flush=True)
        if not running:
            break
        time.sleep(0.5)
    if timings:
        print("the ten slowest:")
        for seconds, name in sorted(timings, reverse=True)[:10]:
            print(f"  {seconds:7.1f} s  {name}")


if __name__ == "__main__":
    main()
