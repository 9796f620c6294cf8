#!/usr/bin/env bash
# The README's test command: installs what is missing, builds (host release) and runs ctest.
# Idempotent; extra arguments go to ctest (e.g. -L unit, -R Ring).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
scripts/bootstrap.sh
cmake --preset host-release >/dev/null
cmake --build --preset host-release
ctest --preset host-release "$@"
