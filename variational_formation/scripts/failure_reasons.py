#!/usr/bin/python3
"""Prints, for every failed test in a catkin test_results tree, one line: the result file and the
start of the failure's message (CI shows the tail of the output, so the reasons go last).

usage: failure_reasons.py TEST_RESULTS_DIR [MAX_CHARS]"""
import os
import sys
import xml.etree.ElementTree as ElementTree


def reasons(root, width):
    for folder, _, files in sorted(os.walk(root)):
        for name in sorted(files):
            if not name.endswith(".xml"):
                continue
            path = os.path.join(folder, name)
            try:
                tree = ElementTree.parse(path)
            except (ElementTree.ParseError, OSError) as e:
                yield f"{name}: unreadable ({e})"
                continue
            for suite in tree.iter("testsuite"):
                told = 0
                for case in suite.iter("testcase"):
                    for bad in list(case.iter("failure")) + list(case.iter("error")):
                        told += 1
                        text = " ".join((bad.get("message") or bad.text or "").split())
                        text = text.split(' File "', 1)[0]  # the message, not the traceback
                        yield f"{name}: {case.get('name')}: {text[:width]}"
                # unittest counts an exception in setUpClass or a module fixture as an error of
                # no test, and rosunit keeps only the count: show the end of the captured output.
                untold = int(suite.get("errors") or 0) + int(suite.get("failures") or 0) - told
                if untold > 0:
                    err = " ".join(((suite.findtext("system-err") or "") + " " +
                                    (suite.findtext("system-out") or "")).split())
                    yield f"{name}: {untold} error(s) outside any test; the end of its output: {err[-width:]}"


if __name__ == "__main__":
    if len(sys.argv) == 2 and sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        sys.exit(0)
    if len(sys.argv) not in (2, 3) or not os.path.isdir(sys.argv[1]):
        sys.exit("usage: failure_reasons.py TEST_RESULTS_DIR [MAX_CHARS]")
    for line in reasons(sys.argv[1], int(sys.argv[2]) if len(sys.argv) == 3 else 400):
        print(line)
