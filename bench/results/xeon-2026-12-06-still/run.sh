#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-06: still bodies left out of the body updates and the narrowphase's
# pose pass (54a620f), and kept lists that follow a break or a re-sort by id instead of rebuilding
# (e0c8a12, blocks from f17da9b). On the lent machine's Xeon: the 824-floe field on one core, 4e89f89 (old), main's step
# before the changes (head, the code of c100981) and afa58db (new6), alternated in 6 rounds;
# 10^5 floes on 1 and 16 threads, head and new6, 3 rounds; then `gem bench --table cpu` of new6.
# Run from the repository root with .gpu-stage-cpu carried (see ../h100-2026-12-05-cpu/xeon.sh);
# writes under $OUT.
R=$PWD
SCALING=0 PERF=0 ROUNDS_824=${ROUNDS_824:-6} ORDER_824="old head new6" NEW=new6 BUILDS="head new6" ROUNDS_1E5=${ROUNDS_1E5:-3} TABLE=1 \
  bash "$R/bench/results/h100-2026-12-05-cpu/xeon.sh"
