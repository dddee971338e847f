#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-06 afternoon: the kept lists keep the last answer of each chunk of 256
# listed pairs whose bodies are all still (f1465c1). On the lent machine's Xeon: the 824-floe field
# on one core, 4e89f89 (old), e8a1613 (main) and f1465c1 (new), alternated; 10^5 floes on 1 and 16
# threads, main, 6d5b466 (still: the displacement checks skipped, every pair filtered) and new.
# Run from the repository root with .gpu-stage-cpu carried (see ../h100-2026-12-05-cpu/xeon.sh);
# writes under $OUT.
R=$PWD
SCALING=0 PERF=0 ROUNDS_824=${ROUNDS_824:-6} ORDER_824="old main new" NEW=new BUILDS="main still new" ROUNDS_1E5=${ROUNDS_1E5:-3} TABLE=0 \
  bash "$R/bench/results/h100-2026-12-05-cpu/xeon.sh"
