#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-07 (session 27), for a lent machine's Xeon: the renames' serial parts
# on the pool (s37, 14279fb) against main before (s36, fd81edd). run-1 and run-2: 10^5 floes at 1
# to 16 threads, the builds in turn and then reversed, with GEM_CPU_TIMING=1, and the 824-floe
# field on one pinned core against old (4e89f89) in ROUNDS (10) alternated rounds
# (../xeon-2026-12-06f-pool/diagnose.sh). caps.txt: an experiment-only build (x-cap: s37 with
# GEM_EXP_TASK_CAP capping the tasks of every parallelRanges round, a patch not kept) on 16
# threads with caps of 32, 64 and 128 against s37, three alternated rounds. Run from the repository
# root with .gpu-stage-cpu carried; writes under $OUT.
R=$PWD; S=$R/.gpu-stage-cpu; OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
D="$R/bench/results/xeon-2026-12-06f-pool/diagnose.sh"
BUILDS="s36 s37" THREADS="1 2 4 8 16" ROUNDS_824=${ROUNDS:-10} OUT=$OUT/run-1 bash "$D"
BUILDS="s37 s36" THREADS="16 8 4 2 1" ROUNDS_824=0 OUT=$OUT/run-2 bash "$D"
L="$S/lib/ld-linux-x86-64.so.2"
capped() {  # capped BUILD CAP: 10^5 floes on 16 threads, the tasks of a round capped at CAP (none: empty)
  local text
  text=$(cd /tmp && GEM_EXP_TASK_CAP=$2 GEM_SCENARIOS=$R/scenarios GEM_CPU_TIMING=1 $L --library-path $S/$1:$S/lib $S/$1/gem \
    bench --backend cpu --cases 100000 --steps 60000 --threads 16 2>&1)
  echo "$1 cap ${2:-none}: $(echo "$text" | grep -E '^10\^5 ' | sed 's/  */ /g' | awk '{for (i = 1; i <= NF; ++i) if ($i == "variable_radius") print $(i + 2)}') ms"
  echo "$text" | grep '^gem cpu' | sed 's/^/  /'
}
for r in 1 2 3; do
  for c in "s37 " "x-cap 32" "x-cap 64" "x-cap 128"; do capped $c; done | tee -a "$OUT/caps.txt"
done
