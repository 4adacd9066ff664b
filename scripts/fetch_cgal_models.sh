#!/usr/bin/env bash
# Test models for `beamcast slim fit` (issue 16) from Debian's libcgal-demo
# package, without installing it: `apt-get download` the .deb into a temporary
# directory, unpack it there with `dpkg-deb -x`, and take the meshes out of
# the data archive inside it (libcgal-demo 5.5.1-2 in bookworm ships
# /usr/share/doc/libcgal-dev/data.tar.gz with data/meshes/bunny00.off,
# fandisk.off, fandisk_large.off and armadillo.off). Nothing is committed:
# the models land in DIR only.
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
dest=$1
models=(bunny00.off fandisk.off fandisk_large.off armadillo.off)

have_all=1
for m in "${models[@]}"; do [ -s "$dest/$m" ] || have_all=0; done
if [ $have_all = 1 ]; then
  echo "fetch_cgal_models: models already in $dest"
  exit 0
fi

for tool in apt-get dpkg-deb tar; do
  command -v $tool >/dev/null || { echo "fetch_cgal_models: $tool not found" >&2; exit 1; }
done
mkdir -p "$dest"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# apt-get download writes into the current directory; as root it warns that
# the _apt user cannot write there (harmless: the download is unsandboxed).
deb=""
if (cd "$tmp" && apt-get download libcgal-demo >"$tmp/apt.log" 2>&1); then
  deb=$(find "$tmp" -maxdepth 1 -name 'libcgal-demo_*.deb' | head -n 1)
fi
if [ -z "$deb" ]; then
  # A copy apt already fetched (e.g. apt-get install --download-only).
  deb=$(find /var/cache/apt/archives -maxdepth 1 -name 'libcgal-demo_*.deb' 2>/dev/null | head -n 1 || true)
fi
if [ -z "$deb" ]; then
  echo "fetch_cgal_models: could not download libcgal-demo:" >&2
  sed 's/^/  /' "$tmp/apt.log" >&2 || true
  exit 2
fi

dpkg-deb -x "$deb" "$tmp/pkg"
# The data archive's location has moved between CGAL releases: look for it.
archive=$(find "$tmp/pkg" -name 'data.tar*' | head -n 1)
if [ -z "$archive" ]; then
  echo "fetch_cgal_models: no data archive in $(basename "$deb")" >&2
  exit 1
fi
members=$(tar -tf "$archive" | grep -E '/(bunny[^/]*|fandisk[^/]*|armadillo[^/]*)\.off$' || true)
if [ -z "$members" ]; then
  echo "fetch_cgal_models: no bunny/fandisk/armadillo .off in $archive" >&2
  exit 1
fi
mkdir -p "$tmp/data"
# shellcheck disable=SC2086  # member names have no spaces
tar -xf "$archive" -C "$tmp/data" $members
for f in $members; do
  cp "$tmp/data/$f" "$dest/"
  echo "fetch_cgal_models: $dest/$(basename "$f") ($(stat -c %s "$tmp/data/$f") bytes)"
done
