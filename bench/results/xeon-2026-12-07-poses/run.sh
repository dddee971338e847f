#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-07, for a lent machine's Xeon: ../xeon-2026-12-06f-pool/diagnose.sh
# twice. Builds: s24 (b181cfd, main before this session), s25 (23ea3e3: the body updates make the
# moved bodies' world vertices and boxes and the narrowphase's pose flags) and s27 (9da3728: also
# the kept lists name the resting stretches of their output, 549490a, and the box pass is split by
# the candidates it reads). run-1: 10^5 floes at 1, 2, 4, 8 and 16 threads, build after build in
# BUILDS_1, with the phase and pool lines, then the 824-floe field on one pinned core, old
# (4e89f89) against them, ROUNDS (8) alternated rounds. run-2: the 10^5 rows again, the builds in
# BUILDS_2 (reversed) and the thread counts reversed. Run from the repository root with
# .gpu-stage-cpu carried; writes under $OUT. The first record (record/, 02:14 UTC) ran with
# BUILDS_1="s24 s25", BUILDS_2="s25 s24"; the second (record-2/) with the defaults.
R=$PWD; OUT=${OUT:-/tmp/out}
D="$R/bench/results/xeon-2026-12-06f-pool/diagnose.sh"
BUILDS="${BUILDS_1:-s24 s25 s27}" THREADS="1 2 4 8 16" ROUNDS_824=${ROUNDS:-8} OUT=$OUT/run-1 bash "$D"
BUILDS="${BUILDS_2:-s27 s25 s24}" THREADS="16 8 4 2 1" ROUNDS_824=0 OUT=$OUT/run-2 bash "$D"
