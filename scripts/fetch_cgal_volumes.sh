#!/usr/bin/env bash
# Test volumes for the volume ray caster (issue 17) from Debian's
# libcgal-demo package: data/images/skull_2.9.inr (64^3 float, a sparse
# skull) and liver.inr.gz (438 x 353 x 165 uint8, gzip-compressed) of its
# data archive, fetched by scripts/fetch_cgal_data.sh (which says how;
# nothing is installed or committed).
#
#   scripts/fetch_cgal_volumes.sh DIR
#
# Exits 0 with the volumes in DIR (already there: nothing is downloaded),
# 2 if the package cannot be downloaded (no network, no apt sources), 1 on
# any other failure.
set -euo pipefail

if [ $# -ne 1 ]; then
  echo "usage: $0 DIR" >&2
  exit 1
fi
exec "$(dirname "$0")/fetch_cgal_data.sh" "$1" skull_2.9.inr liver.inr.gz
