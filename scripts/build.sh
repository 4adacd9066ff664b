#!/usr/bin/env bash
# Configures (once) and builds everything into build/ (binaries in build/bin/).
#   build.sh run    the service and the CLI only: run-time packages, no tests (scripts/run.sh)
#   build.sh        with the tests (scripts/test.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
mode="${1:-test}"
"$(dirname "$0")/install-deps.sh" "$mode"
testing=ON
if [ "$mode" = run ]; then testing=OFF; fi
# Configured once; again when the tests are wanted in a tree configured without them.
if [ ! -f build/build.ninja ] ||
   { [ "$testing" = ON ] && grep -q '^BUILD_TESTING:BOOL=OFF' build/CMakeCache.txt; }; then
  cmake --preset default -DBUILD_TESTING="$testing" >/dev/null
fi
cmake --build build -j"$(nproc)"
