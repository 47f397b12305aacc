#!/usr/bin/env bash
# The README's demo command, from the repository's root: the package's own script does the work.
exec "$(dirname "${BASH_SOURCE[0]}")/../variational_formation/scripts/demo.sh" "$@"
