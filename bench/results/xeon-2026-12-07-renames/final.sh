#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-07 (session 27), for a lent machine's Xeon: the session's final code
# (s38, 31b104d) against main before it (s36, fd81edd). run-1 and run-2: 10^5 floes at 1 to 16
# threads, the builds in turn and then reversed, with GEM_CPU_TIMING=1, and the 824-floe field on
# one pinned core against old (4e89f89) in ROUNDS (12) alternated rounds
# (../xeon-2026-12-06f-pool/diagnose.sh). Run from the repository root with .gpu-stage-cpu
# carried; writes under $OUT.
R=$PWD; OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
D="$R/bench/results/xeon-2026-12-06f-pool/diagnose.sh"
BUILDS="s36 s38" THREADS="1 2 4 8 16" ROUNDS_824=${ROUNDS:-12} OUT=$OUT/run-1 bash "$D"
BUILDS="s38 s36" THREADS="16 8 4 2 1" ROUNDS_824=0 OUT=$OUT/run-2 bash "$D"
