#!/usr/bin/env bash
# `beamcast slim fit` on Debian's CGAL demo models (bunny, fandisk), fetched
# by scripts/fetch_cgal_models.sh into MODELS_DIR: every sample point
# covered and the RMS error under E at E = 0.01. Skips (77) when the package
# cannot be downloaded. Reports land in OUT_DIR.
#   tests/slim_cgal_models.sh BEAMCAST MODELS_DIR OUT_DIR
set -euo pipefail
beamcast=$1 models=$2 out=$3
here=$(cd "$(dirname "$0")" && pwd)
rc=0
"$here/../scripts/fetch_cgal_models.sh" "$models" || rc=$?
if [ $rc = 2 ]; then
  echo "libcgal-demo could not be downloaded: skipped"
  exit 77
fi
[ $rc = 0 ] || exit $rc
mkdir -p "$out"
for m in bunny00 fandisk; do
  "$beamcast" slim fit "$models/$m.off" --out "$out/$m.bslm" --error 0.01 >"$out/$m.json"
  cat "$out/$m.json"
  python3 - "$out/$m.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["spheres"] > 100, r
assert r["uncovered"] == 0, r
assert r["error_rms"] < 0.01, r
PY
done
