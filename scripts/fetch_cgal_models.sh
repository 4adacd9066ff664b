#!/usr/bin/env bash
# Test models for `beamcast slim fit` (issue 16) from Debian's libcgal-demo
# package: data/meshes/bunny00.off, fandisk.off, fandisk_large.off and
# armadillo.off of its data archive, fetched by scripts/fetch_cgal_data.sh
# (which says how; nothing is installed or committed).
#
#   scripts/fetch_cgal_models.sh DIR
#
# Exits 0 with the models in DIR (already there: nothing is downloaded),
# 2 if the package cannot be downloaded (no network, no apt sources), 1 on
# any other failure.
set -euo pipefail

if [ $# -ne 1 ]; then
  echo "usage: $0 DIR" >&2
  exit 1
fi
exec "$(dirname "$0")/fetch_cgal_data.sh" "$1" bunny00.off fandisk.off fandisk_large.off armadillo.off
