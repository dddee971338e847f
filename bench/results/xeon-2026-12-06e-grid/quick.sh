#!/usr/bin/env bash
# quick: scaling of main and new at 10^5
R=$PWD
SCALING=1 SCALING_BUILDS="main new" PERF=1 ROUNDS_824=0 NEW=new BUILDS="main new" ROUNDS_1E5=0 TABLE=0 \
  bash "$R/bench/results/h100-2026-12-05-cpu/xeon.sh"
