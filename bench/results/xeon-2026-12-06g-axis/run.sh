#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-06 late, for a lent machine's Xeon: ../xeon-2026-12-06f-pool/diagnose.sh
# twice. Builds: final2 (1c60427, main before these changes) and s24 (b181cfd: the kept edge tried
# without an early exit, 5e0cd0f; the contact force taken when asked, 1e7003d; the clipping's
# tolerance from the boxes, b181cfd). run-1: 10^5 floes at 1, 2, 4, 8 and 16 threads, final2 then
# s24, with the phase and pool lines, then the 824-floe field on one pinned core, old (4e89f89)
# against both, ROUNDS (8) alternated rounds. run-2: the 10^5 rows again, s24 first and the thread
# counts reversed. Run from the repository root with .gpu-stage-cpu carried; writes under $OUT.
R=$PWD; OUT=${OUT:-/tmp/out}
D="$R/bench/results/xeon-2026-12-06f-pool/diagnose.sh"
BUILDS="final2 s24" THREADS="1 2 4 8 16" ROUNDS_824=${ROUNDS:-8} OUT=$OUT/run-1 bash "$D"
BUILDS="s24 final2" THREADS="16 8 4 2 1" ROUNDS_824=0 OUT=$OUT/run-2 bash "$D"
