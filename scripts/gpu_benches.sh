#!/usr/bin/env bash
# The one call that checks a machine with a GPU (docs/performance.md, "On a
# GPU"). First every GL, stability and server test binary, each run as one
# whole process with --gtest_shuffle --gtest_repeat=2 (tests sharing a
# process and its renderers, as a server's workers do; the three binaries
# side by side, TESTS_LIMIT seconds each, default 240), summed up in
# tests.txt; then the benchmarks in order of what matters most, each under
# its own time limit so a short lease still brings back the first ones:
#
#   scripts/gpu_benches.sh OUT [DATA]
#
# OUT   results: one folder per step, log.txt (each step's command, seconds,
#       exit status), info.txt (the EGL device path's renderer string)
# DATA  optional folder with bunny00.bslm, bunny00.off, fandisk.bslm,
#       fandisk.off (scripts/fetch_cgal_models.sh, then `beamcast slim fit`)
#       and skull_2.9.inr (scripts/fetch_cgal_volumes.sh); steps that need a
#       missing file leave it out
#
# Environment: BIN (folder of beamcast, beamcast-server and the test
# binaries; default build/bin; scripts/gpu_pack.sh packs one with its
# libraries for a machine without this project's packages), DEADLINE (seconds for the whole run; default 3600),
# BEAMCAST_PYTHON (the Python with numpy and matplotlib; default
# /usr/bin/python3), ONLY (space-separated names of the bench steps to run;
# default all). A step over its limit is stopped (exit 124 in log.txt)
# and the next one runs; `tar` of OUT after each step keeps OUT.tgz current.
set -uo pipefail

if [ $# -lt 1 ] || [ $# -gt 2 ]; then
  echo "usage: $0 OUT [DATA]" >&2
  exit 1
fi
out=$1
data=${2:+$(cd "$2" && pwd)}
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${BIN:-$root/build/bin}
deadline=$((SECONDS + ${DEADLINE:-3600}))
py=${BEAMCAST_PYTHON:-/usr/bin/python3}
mkdir -p "$out"
log=$out/log.txt

# step NAME LIMIT_S COMMAND...: runs COMMAND with its output in OUT/NAME.log,
# stopped after LIMIT_S or at the deadline, whichever comes first.
step() {
  local name=$1 limit=$2
  shift 2
  if [ -n "${ONLY:-}" ] && [[ " $ONLY " != *" $name "* ]]; then
    return
  fi
  local left=$((deadline - SECONDS - 5))
  if [ "$left" -lt 15 ]; then
    echo "$name: skipped (deadline)" >>"$log"
    return
  fi
  [ "$limit" -gt "$left" ] && limit=$left
  local t0=$SECONDS
  timeout --kill-after=5 "$limit" "$@" >"$out/$name.log" 2>&1
  local rc=$?
  echo "$name: rc $rc, $((SECONDS - t0)) s (limit $limit): $*" >>"$log"
  pack
}

# OUT.tgz: text and plots, not the raw float images the benches keep
# (*.rgb32f, work/ folders: tens of MB), so it can be brought back.
pack() {
  tar czf "$out.tgz" --exclude='*.rgb32f' --exclude='*/work/*' -C "$(dirname "$out")" \
    "$(basename "$out")" 2>/dev/null
}

have() { [ -n "$data" ] && [ -f "$data/$1" ]; }

{
  date -u
  nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader 2>/dev/null
  "$bin/beamcast" info --platform device 2>&1
} >"$out/info.txt"
renderer=$("$bin/beamcast" info --platform device 2>/dev/null | head -1)
echo "renderer: $renderer" >>"$log"

# The test binaries, side by side (one GPU, 16 cores), whole processes.
tests_limit=${TESTS_LIMIT:-240}
t0=$SECONDS
for t in beamcast_gl_tests beamcast_stability_tests beamcast_server_tests; do
  if [ ! -x "$bin/$t" ]; then
    echo "$t: missing" >>"$log"
    continue
  fi
  (
    timeout --kill-after=5 "$tests_limit" "$bin/$t" --gtest_shuffle --gtest_repeat=2 \
      >"$out/$t.log" 2>&1
    echo "$t: rc $?, $((SECONDS - t0)) s (limit $tests_limit): --gtest_shuffle --gtest_repeat=2" \
      >>"$log"
  ) &
done
wait
{
  for t in beamcast_gl_tests beamcast_stability_tests beamcast_server_tests; do
    [ -f "$out/$t.log" ] || continue
    echo "== $t"
    grep -E "^\[  (PASSED|FAILED|SKIPPED) +\]|tests? from .* ran|^Note: Randomizing|^Repeating all tests|Segmentation|Aborted|KHR_debug" \
      "$out/$t.log" | sort | uniq -c
  done
} >"$out/tests.txt"
pack

slim_pairs=()
slim_args=()
for m in bunny00 fandisk; do
  if have "$m.bslm" && have "$m.off"; then
    slim_pairs+=("$m.bslm:$m.off")
    slim_args+=(--model "$data/$m.bslm" --mesh "$data/$m.off")
  fi
done
frame_args=()
[ ${#slim_pairs[@]} -gt 0 ] && frame_args=(--assets "$data" --slim "${slim_pairs[@]}")
skull_args=()
have skull_2.9.inr && skull_args=(--skull "$data/skull_2.9.inr")

step frames 150 "$py" "$root/bench/frame_times.py" --out "$out/frames" --server "$bin/beamcast-server" \
  --sizes 512 2048 --info "$renderer" "${frame_args[@]}"
# cornell_caustic as shipped, the specular pass on the GPU ("gpu") and on the
# CPU ("cpu"): frame times and error against the path tracer (issue 39).
step caustic_512 90 "$py" "$root/bench/caustic_gpu_bench.py" --binary "$bin/beamcast" \
  --views 3 --rounds 2 --ref-size 128 --spp 64 --out "$out/caustic_512"
step accuracy_512 150 "$bin/beamcast" bench accuracy --size 512 --out "$out/accuracy_512"
step views_512 90 "$bin/beamcast" bench views --size 512 --out "$out/views_512"
step slim_512 90 "$bin/beamcast" bench slim --size 512 --out "$out/slim_512" "${slim_args[@]}"
step volumes_512 90 "$bin/beamcast" bench volumes --size 512 --out "$out/volumes_512" \
  "${skull_args[@]}"
step gi_512 120 "$bin/beamcast" bench gi --size 512 --spp 256 --out "$out/gi_512"
step views_2048 90 "$bin/beamcast" bench views --size 2048 -k 1 -k 4 -k 16 --rounds 2 --out "$out/views_2048"
step accuracy_2048 120 "$bin/beamcast" bench accuracy --size 2048 --out "$out/accuracy_2048" \
  --scene paper_10sets --scene grazing_capsule --scene beams_1000 --scene density_gaussian
step slim_2048 90 "$bin/beamcast" bench slim --size 2048 --zoom-only --zoom 1 --zoom 4 \
  --out "$out/slim_2048" "${slim_args[@]}"
step volumes_2048 90 "$bin/beamcast" bench volumes --size 2048 --reference-spv 2 \
  --out "$out/volumes_2048" "${skull_args[@]}"
step medium_512 60 "$bin/beamcast" bench medium --size 512 --out "$out/medium_512"
# The preview's moving frames at 1080p, JPEG against VP9 and AV1 with the
# encoder threads a 1080p stream gets on a machine of 4 or more cores (issue
# 42: encode time per frame on the GPU machine's CPU; bytes and PSNR).
step video_1080 90 "$bin/beamcast_bench_video" --scene paper_10sets --size 1920x1080 --frames 60 \
  --threads 4 --codecs vp9,av1 --kbps 1000,2000 --jpeg 50 --csv "$out/video_1080.csv"
echo "done: $((SECONDS)) s" >>"$log"
pack
exit 0
