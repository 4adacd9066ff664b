#!/usr/bin/env bash
# Installs the Debian 12 packages Beamcast builds, runs and tests with.
# Skips apt entirely when everything is already installed.
set -euo pipefail

PACKAGES=(
  cmake ninja-build g++ pkg-config
  libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri   # EGL + OpenGL (llvmpipe without a GPU)
  libglm-dev nlohmann-json3-dev libpng-dev libcli11-dev
  libturbojpeg0-dev                                   # JPEG frames of the interactive preview
  libdeflate-dev                                      # PNG frames (render/image.cpp)
  libzstd-dev python3-zstandard                       # raw_zstd frames (server, C++ and Python clients)
  zlib1g-dev                                          # gzip-compressed volume files (NRRD, .inr.gz)
  libembree-dev                                       # photon tracing and the path-traced reference (gi/)
  libnanoflann-dev                                    # k-nearest photons of the CPU gather (gi/)
  glslang-tools                                       # shader compile check in the tests
  libgtest-dev libgmock-dev libbenchmark-dev
  libboost-dev libboost-system-dev
  libssl-dev                                          # TLS of the HTTP listener (--tls-cert)
  clang-14 libclang-rt-14-dev                         # libFuzzer targets (fuzz/, --preset fuzz)
  clang-tidy-14                                       # the clang-tidy stage of scripts/test.sh
  python3 python3-numpy python3-matplotlib            # plots and analysis scripts
  nodejs chromium                                     # the preview page's browser test (ctest -L preview)
  haproxy                                             # several servers behind it (deploy/, ctest -L scaleout)
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# npm: Debian's package, unless the installed nodejs already brings its own
# (NodeSource's nodejs does, and conflicts with Debian's npm).
command -v npm >/dev/null 2>&1 || missing+=(npm)
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "install-deps: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
