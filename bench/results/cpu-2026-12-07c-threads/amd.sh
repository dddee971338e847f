#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-07 (session 29), on the development machine (AMD EPYC, 2 vCPUs):
# 10^5 floes at 1 and 2 threads over the bench's 595 timed steps (--steps 60000) and over 5,995
# (--steps 600000; STEPS picks, both by default), the builds of BUILDS alternated, ROUNDS times,
# with GEM_CPU_TIMING=1 (one thread pinned to core 1);
# then the 824-floe field on core 1, old (4e89f89) and the builds, ROUNDS_824 alternated rounds.
# Run from the repository root: bash bench/results/cpu-2026-12-07c-threads/amd.sh OUTDIR.
R=$PWD; S=$R/.gpu-stage-cpu; L=$S/lib/ld-linux-x86-64.so.2; OUT=$1; mkdir -p "$OUT"
BUILDS=${BUILDS:-"s41 s44"}
export GEM_SCENARIOS=$R/scenarios
{ date -u; nproc; lscpu | head -20; uptime; } > "$OUT/machine.txt" 2>&1
gem() { local b=$1; shift; (cd /tmp && $PIN $L --library-path $S/$b:$S/lib $S/$b/gem "$@"); }
ms() { grep -E '^(10\^5|824) ' | sed 's/  */ /g' | awk '{for (i = 1; i <= NF; ++i) if ($i == "variable_radius") print $(i + 2)}'; }
for r in $(seq ${ROUNDS:-4}); do
  order="$BUILDS"; [ $((r % 2)) = 0 ] && order=$(echo $order | tr ' ' '\n' | tac | tr '\n' ' ')
  for steps in ${STEPS:-60000 600000}; do for b in $order; do for t in 1 2; do
    pin=""; [ $t = 1 ] && pin="taskset -c 1"
    text=$(PIN="$pin" GEM_CPU_TIMING=1 gem $b bench --backend cpu --cases 100000 --threads $t --steps $steps 2>&1)
    echo "round $r steps $steps $b threads $t: $(echo "$text" | ms) ms" >> "$OUT/scaling.txt"
    echo "$text" | grep '^gem cpu' | sed 's/^/  /' >> "$OUT/scaling.txt"
  done; done; done
done
for r in $(seq ${ROUNDS_824:-6}); do
  echo "round $r" >> "$OUT/rounds-824.txt"
  order="old $BUILDS"; [ $((r % 2)) = 0 ] && order=$(echo $order | tr ' ' '\n' | tac | tr '\n' ' ')
  for b in $order; do echo "$b threads 1: $(PIN="taskset -c 1" gem $b bench --backend cpu --cases 824 --threads 1 --steps 4000 2>&1 | ms) ms" >> "$OUT/rounds-824.txt"; done
done
uptime >> "$OUT/machine.txt"
