#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-06 afternoon: the kept lists skip the displacement check of bodies the
# stepper's last step left still, and relist past 3 direct bodies instead of 8 (6d5b466). On the lent
# machine's Xeon: the 824-floe field on one core, 4e89f89 (old), main before the change (main,
# e8a1613) and 6d5b466 (new), alternated; 10^5 floes on 1 and 16 threads, main and new.
# Run from the repository root with .gpu-stage-cpu carried (see ../h100-2026-12-05-cpu/xeon.sh);
# writes under $OUT.
R=$PWD
SCALING=0 PERF=0 ROUNDS_824=${ROUNDS_824:-8} ORDER_824="old main new" NEW=new BUILDS="main new" ROUNDS_1E5=${ROUNDS_1E5:-4} TABLE=0 \
  bash "$R/bench/results/h100-2026-12-05-cpu/xeon.sh"
