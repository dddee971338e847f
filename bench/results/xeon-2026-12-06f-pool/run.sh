#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-06 night, the record run: a1d2653 (base, the code of main before this
# wave of changes) against the final code (final), 10^5 floes on 1 to 16 threads in two rounds of
# alternated order, and the 824-floe field on one core against 4e89f89 (old), alternated. Run from
# the repository root with .gpu-stage-cpu carried (base/, final/ and old/ hold gem and
# libgem_core.so of CPU-only Release builds; ../h100-2026-12-05-cpu/xeon.sh says what else it
# holds); writes under $OUT.
R=$PWD; OUT=${OUT:-/tmp/out}
D="$R/bench/results/xeon-2026-12-06f-pool/diagnose.sh"
BUILDS="base final" THREADS="1 2 4 8 16" ROUNDS_824=0 OUT=$OUT/scaling-1 bash "$D"
BUILDS="final base" THREADS="16 8 4 2 1" ROUNDS_824=0 OUT=$OUT/scaling-2 bash "$D"
BUILDS="base final" THREADS="" ROUNDS_824=${ROUNDS_824:-6} OUT=$OUT/rounds bash "$D"
# The pool's groups alone: pool/ is a1d2653 with the pool's account only (one shared counter),
# groups/ the same with each thread's own group of tasks first (7b0f54a without the ranged removal).
BUILDS="pool groups" THREADS="16" ROUNDS_824=0 OUT=$OUT/groups-1 bash "$D"
BUILDS="groups pool" THREADS="16" ROUNDS_824=0 OUT=$OUT/groups-2 bash "$D"
