#!/usr/bin/env bash
# The service command: installs dependencies, builds, and renders the demo
# scene (the paper's 10 beam sets at 512x512) on the headless GPU path, with
# per-pass timings. Arguments are passed to `beamcast render` after the scene.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
build/bin/beamcast info
build/bin/beamcast render examples/paper_10sets.json --out out/demo "$@"
echo "demo frame: out/demo/view.png"
