#!/usr/bin/env bash
# The README's test command, from the repository's root: the package's own script does the work.
exec "$(dirname "${BASH_SOURCE[0]}")/../variational_formation/scripts/test.sh" "$@"
