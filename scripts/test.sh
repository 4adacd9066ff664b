#!/usr/bin/env bash
# The test command (= CI): installs dependencies, builds everything, runs every
# test; then clang-tidy (.clang-tidy: clang-analyzer-*) over the project's
# sources, the fuzz targets (ctest -L fuzz, clang + libFuzzer, protocol/ only)
# and the suite again under ASan + UBSan (build-asan/), less the labels bench,
# preview and scaleout.
# Extra arguments go to the main ctest run only (e.g. -L image, -R Shaders) and
# skip the clang-tidy, fuzz and sanitizer stages; BEAMCAST_SKIP_ASAN=1 skips the ASan stage.
set -euo pipefail
cd "$(dirname "$0")/.."
launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
stage() { printf '\n== %s (%s)\n' "$1" "$(date -u +%H:%M:%S)"; }

stage "build and test"
scripts/build.sh
# The soak test (label slow) runs for BEAMCAST_SOAK_SECONDS.
export BEAMCAST_SOAK_SECONDS="${BEAMCAST_SOAK_SECONDS:-60}"
ctest --test-dir build --output-on-failure -j"$(nproc)" "$@"
if [ $# -gt 0 ]; then exit 0; fi

stage "clang-tidy"
# clang-analyzer-* (.clang-tidy) over every translation unit of
# build/compile_commands.json in the product's folders, one clang-tidy per
# core, the slowest files first (scripts/clang_tidy.py); any finding fails
# the stage (WarningsAsErrors). tests/ is left out:
# its 38 files cost ~23 s of CPU each against ~11 s for the 56 here (gtest's
# macros through the analyzer): ~14 more minutes of CPU, more than doubling
# the stage; the tests run under ASan + UBSan below. Measured: README.md.
/usr/bin/env python3 scripts/clang_tidy.py build build/clang-tidy.log \
  protocol render gi slim shaders server client cli bench fuzz || {
  echo "clang-tidy: findings above (whole log: build/clang-tidy.log)"
  exit 1
}

stage "fuzz targets"
if [ ! -f build-fuzz/build.ninja ]; then cmake --preset fuzz "${launcher[@]}" >/dev/null; fi
cmake --build build-fuzz -j"$(nproc)"
ctest --test-dir build-fuzz --output-on-failure -j"$(nproc)" -L fuzz

if [ "${BEAMCAST_SKIP_ASAN:-0}" != 1 ]; then
  stage "ASan + UBSan"
  # Compiled by clang-14 (CMakePresets.json): about half of g++'s CPU time
  # for the same build (docs/performance.md, "The test command's time").
  if [ ! -f build-asan/build.ninja ]; then cmake --preset asan "${launcher[@]}" >/dev/null; fi
  cmake --build build-asan -j"$(nproc)"
  # Sanitizer reports fail the test; leaks too (LeakSanitizer at exit).
  export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1"
  # use_tls=0: LeakSanitizer does not read threads' TLS as roots. GCC 12's
  # LSan misreads glibc 2.36's dynamic-TLS table for a dlopen'ed Mesa module
  # ("DTLS 12 at 0x1121-0x1800002223", then "Tracer caught signal 11" at
  # exit, after the test passed); without TLS roots nothing is read there,
  # and anything reachable only from TLS is reported (stricter, not laxer):
  # glibc's own dlopen bookkeeping is suppressed in lsan.supp.
  export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp:print_suppressions=0:use_tls=0"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
  # The soak runs shorter here: same faults, a quarter of the time (ASan's
  # slowdown would otherwise make it the longest step of CI). The stability
  # sweep runs 1/20 of its configurations (every group, same generator): the
  # full 100 000 ran in the first stage; here it looks for memory errors,
  # and the Debug + ASan CPU reference is over 10x slower.
  # The browser and HAProxy tests (labels preview, scaleout) are left out
  # here: they bound reconnects and first frames in wall seconds, which a
  # Debug + ASan server misses on a loaded machine (stop 46's red run), and
  # the server code they drive (HTTP, WebSocket, TLS, restarts) runs under
  # the sanitizers in the server label's tests. Saves ~125 s of the 2 cores.
  BEAMCAST_SOAK_SECONDS=15 BEAMCAST_SWEEP_SIZE=5000 ctest --test-dir build-asan --output-on-failure -j"$(nproc)" -LE 'bench|preview|scaleout'
fi
stage "done"
