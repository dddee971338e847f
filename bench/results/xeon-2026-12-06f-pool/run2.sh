#!/usr/bin/env bash
# The second record run: final2 (1c60427, the filter's join placed range by range on the pool)
# against final (e4fd427) at 10^5 floes on 1, 2 and 16 threads, two rounds of alternated order.
# Same staging as run.sh; writes under $OUT.
R=$PWD; OUT=${OUT:-/tmp/out}
D="$R/bench/results/xeon-2026-12-06f-pool/diagnose.sh"
BUILDS="final final2" THREADS="1 2 16" ROUNDS_824=0 OUT=$OUT/run2-1 bash "$D"
BUILDS="final2 final" THREADS="16 2 1" ROUNDS_824=0 OUT=$OUT/run2-2 bash "$D"
