#!/usr/bin/env bash
# Installs the dependencies, builds, runs every gtest, rostest and Python test (one line each
# as it finishes, then the ten slowest), and ends with "N passed, M failed". Exits non-zero on
# any failure.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
vf_install_dependencies
werror=()
[ -n "${CI:-}" ] && werror=(-DVF_WERROR=ON)
echo "building the package (log: $WS/build.log)"
vf_build "${werror[@]}"
vf_source
cd "$WS"
rm -rf "$WS/build/test_results"
mkdir -p "$WS/build/test_results"
status=0
# Build the tests on every core, then run them one at a time (rostests share the machine),
# with a line per test as it finishes (scripts/test_progress.py) and the ten slowest at the end.
echo "building the tests (log: $WS/tests.log)"
catkin_make tests -j"$(nproc)" >"$WS/tests.log" 2>&1 || status=$?
if [ "$status" -eq 0 ]; then
  echo "running the tests, one at a time: result, seconds, result file"
  catkin_make run_tests -j1 >>"$WS/tests.log" 2>&1 &
  run=$!
  /usr/bin/python3 "$REPO/scripts/test_progress.py" "$WS/build/test_results" "$run" &
  progress=$!
  wait "$run" || status=$?
  wait "$progress" || true
fi
results="$(catkin_test_results "$WS/build/test_results" 2>&1 || true)"
echo "$results" | grep -vE '^Skipping' || true
summary="$(echo "$results" | grep -E '^Summary:' | tail -n 1)"
tests=$(echo "$summary" | sed -nE 's/.* ([0-9]+) tests.*/\1/p')
errors=$(echo "$summary" | sed -nE 's/.* ([0-9]+) errors.*/\1/p')
failures=$(echo "$summary" | sed -nE 's/.* ([0-9]+) failures.*/\1/p')
skipped=$(echo "$summary" | sed -nE 's/.* ([0-9]+) skipped.*/\1/p')
tests=${tests:-0}; errors=${errors:-0}; failures=${failures:-0}; skipped=${skipped:-0}
failed=$((errors + failures))
passed=$((tests - failed - skipped))
# A test node that dies before reporting leaves a result file with no test in it: a failure.
empty=$(grep -lE '<testsuite[^>]* tests="0"' -r "$WS/build/test_results" 2>/dev/null || true)
# Each rostest writes a wrapper (rostest-*.xml) and its test node's own results (rosunit-*.xml,
# named by the unique test-name); a node that died before reporting leaves no inner file.
wrappers=$(find "$WS/build/test_results" -name 'rostest-*.xml' | wc -l)
inner=$(find "$WS/build/test_results" -name 'rosunit-*.xml' | wc -l)
if [ "$inner" -lt "$wrappers" ]; then
  empty="$empty${empty:+$'\n'}$((wrappers - inner)) rostest(s) without their test node's results"
fi
if [ -n "$empty" ]; then
  echo "result files without a single test (a test node died?):" >&2
  echo "$empty" >&2
  failed=$((failed + $(echo "$empty" | wc -l)))
fi
if [ "$tests" -eq 0 ]; then
  echo "no test results found; see $WS/tests.log" >&2
  failed=$((failed + 1))
fi
if [ "$status" -ne 0 ] && [ "$failed" -eq 0 ]; then
  tail -n 40 "$WS/tests.log"
  echo "catkin_make run_tests failed; see $WS/tests.log" >&2
  failed=1
fi
if [ "$failed" -gt 0 ]; then
  echo "why (the start of each failure's message; the whole log is $WS/tests.log):"
  /usr/bin/python3 "$REPO/scripts/failure_reasons.py" "$WS/build/test_results" 400 || true
fi
if [ "$skipped" -gt 0 ]; then
  echo "$passed passed, $failed failed, $skipped skipped"
else
  echo "$passed passed, $failed failed"
fi
[ "$failed" -eq 0 ]
