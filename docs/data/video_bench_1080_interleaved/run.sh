#!/bin/bash
cd /work/main/build
A="--scene paper_10sets --size 1920x1080 --frames 40 --speeds 8 --kbps 1000,4000 --jpeg 50"
for round in 1 2; do
  if [ $round = 1 ]; then order="old new1 new2"; else order="new2 new1 old"; fi
  for v in $order; do
    case $v in
      old) bin/bench_video_oldconv $A --threads 1 --csv /tmp/vi/r${round}_old.csv >/dev/null 2>&1;;
      new1) bin/beamcast_bench_video $A --threads 1 --csv /tmp/vi/r${round}_new1.csv >/dev/null 2>&1;;
      new2) bin/beamcast_bench_video $A --threads 2 --csv /tmp/vi/r${round}_new2.csv >/dev/null 2>&1;;
    esac
    echo "$round $v $(date +%T)" >> /tmp/vi/log
  done
done
echo done > /tmp/vi/DONE
