#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-06 evening: b23a4ad (new: the kept list's direct pass and relisting
# search a grid of the references; the rebuild budget counts each relisted floe once; a rename is
# followed on the pool; relisting rewrites the side list on the pool) against 8aa28e4 (main: the
# code of main before, 05afc91 changing only docs and comments) and 4e89f89 (old) on the lent
# machine's Xeon: the thread scaling of main and new at 10^5 floes, a 16-thread profile of new, the
# 824-floe field on one core (alternated), 10^5 floes on 1 and 16 threads. Run from the repository
# root with .gpu-stage-cpu carried (see ../h100-2026-12-05-cpu/xeon.sh); writes under $OUT.
R=$PWD
SCALING=1 SCALING_BUILDS="main new" PERF=1 ROUNDS_824=${ROUNDS_824:-8} ORDER_824="old main new" NEW=new BUILDS="main new" ROUNDS_1E5=${ROUNDS_1E5:-3} TABLE=0 \
  bash "$R/bench/results/h100-2026-12-05-cpu/xeon.sh"
