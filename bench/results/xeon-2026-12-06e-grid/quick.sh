#!/usr/bin/env bash
# The short run of quick-33ed364/: the thread scaling of main and new at 10^5 floes and a 16-thread
# profile of new, nothing else. Run from the repository root with .gpu-stage-cpu carried (see
# ../h100-2026-12-05-cpu/xeon.sh); writes under $OUT.
R=$PWD
SCALING=1 SCALING_BUILDS="main new" PERF=1 ROUNDS_824=0 NEW=new BUILDS="main new" ROUNDS_1E5=0 TABLE=0 \
  bash "$R/bench/results/h100-2026-12-05-cpu/xeon.sh"
