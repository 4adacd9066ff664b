#!/bin/bash
# Interleaved 1080p encode times (docs/performance.md, "At 1080p with encoder
# threads and a faster colour conversion"). Needs build/bin/bench_video_oldconv:
# beamcast_bench_video built with the conversion of render/video.cpp before
# commit 17b38f8. Usage: run.sh OUTDIR (one CSV per run, as beamcast_bench_video --csv).
set -euo pipefail
out="$(realpath "${1:?usage: run.sh OUTDIR}")"
mkdir -p "$out"
cd "$(dirname "$0")/../../../build"
A="--scene paper_10sets --size 1920x1080 --frames 40 --speeds 8 --kbps 1000,4000 --jpeg 50"
for round in 1 2; do
  if [ $round = 1 ]; then order="old new1 new2"; else order="new2 new1 old"; fi
  for v in $order; do
    case $v in
      old) bin/bench_video_oldconv $A --threads 1 --csv "$out/r${round}_old.csv" >/dev/null 2>&1;;
      new1) bin/beamcast_bench_video $A --threads 1 --csv "$out/r${round}_new1.csv" >/dev/null 2>&1;;
      new2) bin/beamcast_bench_video $A --threads 2 --csv "$out/r${round}_new2.csv" >/dev/null 2>&1;;
    esac
  done
done
