#!/usr/bin/env bash
# Files from Debian's libcgal-demo package, without installing it: `apt-get
# download` the .deb into a temporary directory, unpack it there with
# `dpkg-deb -x`, and take the named files out of the data archive inside it
# (libcgal-demo 5.5.1-2 in bookworm ships /usr/share/doc/libcgal-dev/data.tar.gz,
# with data/meshes/*.off and data/images/*.inr*). Nothing is committed: the
# files land in DIR only. scripts/fetch_cgal_models.sh and
# scripts/fetch_cgal_volumes.sh name what they need.
#
#   scripts/fetch_cgal_data.sh DIR NAME...
#
# NAME is a file name in the archive (its folder does not matter). Exits 0
# with every NAME in DIR (all already there: nothing is downloaded), 2 if
# the package cannot be downloaded (no network, no apt sources), 1 on any
# other failure (a NAME not in the archive included).
set -euo pipefail

me=$(basename "$0" .sh)
if [ $# -lt 2 ]; then
  echo "usage: $0 DIR NAME..." >&2
  exit 1
fi
dest=$1
shift
names=("$@")

have_all=1
for n in "${names[@]}"; do [ -s "$dest/$n" ] || have_all=0; done
if [ $have_all = 1 ]; then
  echo "$me: ${names[*]} already in $dest"
  exit 0
fi

for tool in apt-get dpkg-deb tar; do
  command -v $tool >/dev/null || { echo "$me: $tool not found" >&2; exit 1; }
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
  echo "$me: could not download libcgal-demo:" >&2
  sed 's/^/  /' "$tmp/apt.log" >&2 || true
  exit 2
fi

dpkg-deb -x "$deb" "$tmp/pkg"
# The data archive's location has moved between CGAL releases: look for it.
archive=$(find "$tmp/pkg" -name 'data.tar*' | head -n 1)
if [ -z "$archive" ]; then
  echo "$me: no data archive in $(basename "$deb")" >&2
  exit 1
fi
listing=$(tar -tf "$archive")
members=()
for n in "${names[@]}"; do
  m=$(awk -F/ -v n="$n" '$NF == n { print; exit }' <<<"$listing")
  if [ -z "$m" ]; then
    echo "$me: $n is not in the data archive of $(basename "$deb")" >&2
    exit 1
  fi
  members+=("$m")
done
mkdir -p "$tmp/data"
tar -xf "$archive" -C "$tmp/data" "${members[@]}"
for m in "${members[@]}"; do
  cp "$tmp/data/$m" "$dest/"
  echo "$me: $dest/$(basename "$m") ($(stat -c %s "$tmp/data/$m") bytes)"
done
