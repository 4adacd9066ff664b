#!/usr/bin/env bash
# The test command: installs dependencies, builds everything, runs every test.
# Extra arguments go to ctest (e.g. -L image, -R Shaders).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" "$@"
