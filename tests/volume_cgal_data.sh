#!/usr/bin/env bash
# The scene parser on Debian's CGAL demo volumes (skull_2.9.inr, liver.inr.gz),
# fetched by scripts/fetch_cgal_volumes.sh into VOLUMES_DIR: the unit test
# VolumeCgal.SkullAndLiverParse run with them. Skips (77) when the package
# cannot be downloaded.
#   tests/volume_cgal_data.sh UNIT_TESTS VOLUMES_DIR
set -euo pipefail
unit_tests=$1 volumes=$2
here=$(cd "$(dirname "$0")" && pwd)
rc=0
"$here/../scripts/fetch_cgal_volumes.sh" "$volumes" || rc=$?
if [ $rc = 2 ]; then
  echo "libcgal-demo could not be downloaded: skipped"
  exit 77
fi
[ $rc = 0 ] || exit $rc
# A filter that matches nothing passes, and so does a skipped test: the
# output must show the test's OK line.
out=$(BEAMCAST_CGAL_VOLUMES="$volumes" "$unit_tests" --gtest_filter='VolumeCgal.*' 2>&1) || {
  echo "$out"
  exit 1
}
echo "$out"
grep -q '^\[       OK \] VolumeCgal.SkullAndLiverParse' <<<"$out"
