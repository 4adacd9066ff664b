#!/usr/bin/env bash
# Installs the Debian 12 packages Beamcast builds, runs and tests with:
#   install-deps.sh run    what building and running the service needs (scripts/run.sh)
#   install-deps.sh        that and what the tests need (scripts/test.sh)
#   install-deps.sh MODE --list    prints the packages, installs nothing
# Skips apt entirely when everything is already installed.
set -euo pipefail
mode="${1:-test}"
list="${2:-}"
case "$mode" in run|test) ;; *) echo "usage: install-deps.sh [run|test]" >&2; exit 2 ;; esac

# Building and running beamcast-server and beamcast.
RUN_PACKAGES=(
  cmake ninja-build g++ pkg-config
  libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri   # EGL + OpenGL (llvmpipe without a GPU)
  libglm-dev nlohmann-json3-dev libpng-dev libcli11-dev
  libturbojpeg0-dev                                   # JPEG frames of the interactive preview
  libvpx-dev                                          # VP8/VP9 video frames of the preview
  libaom-dev                                          # AV1 video frames of the preview
  libdeflate-dev                                      # PNG frames (render/image.cpp)
  libzstd-dev python3-zstandard                       # raw_zstd frames (server, C++ and Python clients)
  zlib1g-dev                                          # gzip-compressed volume files (NRRD, .inr.gz)
  libembree-dev                                       # photon tracing and the path-traced reference (gi/)
  libnanoflann-dev                                    # k-nearest photons of the CPU gather (gi/)
  libbenchmark-dev                                    # `beamcast bench` (bench/, linked into the CLI)
  libboost-dev libboost-system-dev
  libssl-dev                                          # TLS of the HTTP listener (--tls-cert)
)
# The tests and the development tools on top (scripts/test.sh).
TEST_PACKAGES=(
  glslang-tools                                       # shader compile check in the tests
  libgtest-dev libgmock-dev
  clang-14 libclang-rt-14-dev                         # libFuzzer targets (--preset fuzz) and the sanitizer build (--preset asan)
  clang-tidy-14                                       # the clang-tidy stage of scripts/test.sh
  lld                                                 # linker of the builds (CMakeLists.txt), 5x GNU ld's speed
  python3 python3-numpy python3-matplotlib            # plots and analysis scripts
  nodejs chromium                                     # the preview page's browser test (ctest -L preview)
  haproxy                                             # several servers behind it (deploy/, ctest -L scaleout)
  curl                                                # POST /v1/render as the guide shows it (cli.first_hour)
)
PACKAGES=("${RUN_PACKAGES[@]}")
if [ "$mode" = test ]; then PACKAGES+=("${TEST_PACKAGES[@]}"); fi
if [ "$list" = --list ]; then printf '%s\n' "${PACKAGES[@]}"; exit 0; fi

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# npm (tests): Debian's package, unless the installed nodejs already brings its
# own (NodeSource's nodejs does, and conflicts with Debian's npm).
if [ "$mode" = test ]; then command -v npm >/dev/null 2>&1 || missing+=(npm); fi
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "install-deps: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
