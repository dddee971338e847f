#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-06: libgem_core built so that its calls to its own functions bind
# directly (7306c08: -fno-semantic-interposition, -fno-plt, -Bsymbolic-functions; the step's code
# unchanged). On the lent machine's Xeon: the 824-floe field on one core, 4e89f89 (old), main's
# step before the change (head, the code of c100981) and the change (new3), alternated in 10
# rounds; then 10^5 floes on 1 and 16 threads, head and new3, 3 rounds. Run from the repository
# root with .gpu-stage-cpu carried (see ../h100-2026-12-05-cpu/xeon.sh); writes under $OUT.
R=$PWD
SCALING=0 PERF=0 ROUNDS_824=${ROUNDS_824:-10} ORDER_824="old head new3" NEW=new3 BUILDS="head new3" ROUNDS_1E5=${ROUNDS_1E5:-3} \
  bash "$R/bench/results/h100-2026-12-05-cpu/xeon.sh"
