#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-07 (session 28), on the development machine (AMD EPYC, 2 vCPUs):
# the 824-floe field in ROUNDS (10) alternated rounds of old, s39 and s41 pinned to core 1, then
# 10^5 floes at 1 and 2 threads, s39 and s41 in turn, ROUNDS5 (3) times. Run from the repository
# root: bash bench/results/xeon-2026-12-07b-profile/amd.sh OUTDIR (amd/ is such a run).
R=$PWD; S=$R/.gpu-stage-cpu; L=$S/lib/ld-linux-x86-64.so.2; OUT=$1; mkdir -p $OUT
export GEM_SCENARIOS=$R/scenarios
gem() { local b=$1; shift; (cd /tmp && $PIN $L --library-path $S/$b:$S/lib $S/$b/gem "$@"); }
ms() { grep -E '^(10\^5|824) ' | sed 's/  */ /g' | awk '{for (i = 1; i <= NF; ++i) if ($i == "variable_radius") print $(i + 2)}'; }
for r in $(seq ${ROUNDS:-10}); do
  echo "round $r" >> $OUT/rounds-824.txt
  order="old s39 s41"; [ $((r % 2)) = 0 ] && order="s41 s39 old"
  for b in $order; do echo "$b threads 1: $(PIN="taskset -c 1" gem $b bench --backend cpu --cases 824 --threads 1 --steps 4000 2>&1 | ms) ms" >> $OUT/rounds-824.txt; done
done
for r in $(seq ${ROUNDS5:-3}); do
  for b in s39 s41; do for t in 1 2; do
    pin=""; [ $t = 1 ] && pin="taskset -c 1"
    text=$(PIN="$pin" GEM_CPU_TIMING=1 gem $b bench --backend cpu --cases 100000 --threads $t --steps 60000 2>&1)
    echo "round $r $b threads $t: $(echo "$text" | ms) ms" >> $OUT/scaling.txt
    echo "$text" | grep "steps by kind" | sed 's/^/  /' >> $OUT/scaling.txt
  done; done
done
