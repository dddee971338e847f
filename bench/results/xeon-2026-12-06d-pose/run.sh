#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-06 afternoon: 8aa28e4 (new: the chunked filter, and the narrowphase's
# pose pass through local pointers) against e8a1613 (main) and 4e89f89 (old) on the lent machine's
# Xeon: the 824-floe field on one core, alternated; 10^5 floes on 1 and 16 threads; the thread
# scaling of new. Run from the repository root with .gpu-stage-cpu carried (see
# ../h100-2026-12-05-cpu/xeon.sh); writes under $OUT.
R=$PWD
SCALING=1 SCALING_BUILDS=new PERF=0 ROUNDS_824=${ROUNDS_824:-8} ORDER_824="old main new" NEW=new BUILDS="main new" ROUNDS_1E5=${ROUNDS_1E5:-3} TABLE=0 \
  bash "$R/bench/results/h100-2026-12-05-cpu/xeon.sh"
