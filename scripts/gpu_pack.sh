#!/usr/bin/env bash
# Packs what scripts/gpu_benches.sh needs on a machine with a GPU but without
# this project's Debian packages: the built programs and test binaries,
# stripped, in DIR/bin, and the shared libraries they load that are not the C
# and C++ runtime or GL/EGL (the GPU machine's driver and glvnd provide
# those) in DIR/lib.
#
#   scripts/gpu_pack.sh DIR [BUILD]      (BUILD: default build)
#
# There, in the checkout: LD_LIBRARY_PATH=DIR/lib BEAMCAST_DATA_DIR=$PWD
# BIN=DIR/bin scripts/gpu_benches.sh OUT (the benches find examples/ and
# bench/ through BEAMCAST_DATA_DIR). The test binaries read examples/ and
# protocol/ from the source folder they were built in (BEAMCAST_SOURCE_DIR):
# link that path to the checkout there. docs/data/gpu-2026-11-27/README.md
# has the whole command of a run.
set -euo pipefail
if [ $# -lt 1 ] || [ $# -gt 2 ]; then
  echo "usage: $0 DIR [BUILD]" >&2
  exit 1
fi
dir=$1
build=${2:-build}
root=$(cd "$(dirname "$0")/.." && pwd)
programs=(beamcast beamcast-server beamcast_gl_tests beamcast_stability_tests
          beamcast_server_tests beamcast_bench_video)
rm -rf "$dir"
mkdir -p "$dir/bin" "$dir/lib"
for p in "${programs[@]}"; do
  src=$root/$build/bin/$p
  [ -x "$src" ] || { echo "gpu_pack: $src missing (build it first)" >&2; exit 1; }
  strip -o "$dir/bin/$p" "$src"
done
# Libraries by the path the loader resolves here; the base system and GL stay.
skip='^(libc|libm|libstdc\+\+|libgcc_s|libpthread|libdl|librt|ld-linux[^ ]*|libEGL|libGL|libGLX|libGLdispatch|libOpenGL|libgbm|libdrm)\.so'
for p in "${programs[@]}"; do
  ldd "$dir/bin/$p" | awk '$2 == "=>" && $3 ~ /^\// {print $1, $3}'
done | sort -u | while read -r name path; do
  if [[ ! $name =~ $skip ]]; then cp -L "$path" "$dir/lib/$name"; fi
done
du -sh "$dir"
