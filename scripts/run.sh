#!/usr/bin/env bash
# The service command: installs dependencies, builds, and starts beamcast-server
# on 127.0.0.1:7878 with embedded defaults (llvmpipe or the first GPU, the
# paper's 10 beam sets preloaded as scene "demo"). Extra arguments go to the
# server (e.g. --port 0, --device 1, --render-workers 2; see --help).
set -euo pipefail
cd "$(dirname "$0")/.."
# Only what running needs: no test packages, no test binaries.
scripts/build.sh run
exec build/bin/beamcast-server "$@"
