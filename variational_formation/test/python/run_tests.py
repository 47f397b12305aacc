#!/usr/bin/python3
"""Runs Python unittest files and writes one JUnit XML result file (what catkin_test_results and
scripts/test.sh read). CMake registers each group with catkin_run_tests_target (cmake/python.cmake).

usage: run_tests.py RESULT_XML TEST_FILE...
Exit status 0 if every test passed, 1 otherwise."""
import importlib.util
import os
import sys
import unittest

from rosunit import xmlrunner


def load(path):
    """The tests of one file, imported under its own name (its folder first on sys.path, so that
    it finds the shared harness beside it)."""
    folder = os.path.dirname(os.path.abspath(path))
    if folder not in sys.path:
        sys.path.insert(0, folder)
    name = os.path.splitext(os.path.basename(path))[0]
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return unittest.defaultTestLoader.loadTestsFromModule(module)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    result_file, files = sys.argv[1], sys.argv[2:]
    suite = unittest.TestSuite(load(f) for f in files)
    os.makedirs(os.path.dirname(os.path.abspath(result_file)), exist_ok=True)
    with open(result_file, "w") as stream:
        stream.write('<?xml version="1.0" encoding="utf-8"?>\n')
        result = xmlrunner.XMLTestRunner(stream=stream).run(suite)
    if not result.wasSuccessful():
        for test, trace in result.failures + result.errors:
            print(f"FAILED {test}:\n{trace}", file=sys.stderr)
    sys.exit(0 if result.wasSuccessful() else 1)


if __name__ == "__main__":
    main()
