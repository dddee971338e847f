#!/usr/bin/env bash
# The development machine (2 vCPUs): 10^5 floes on 1 and 2 threads, base (a1d2653) against final,
# ROUNDS rounds of alternated order; then the 824-floe field on one core, old, base and final
# alternated. Same staging as run.sh; writes under $OUT.
R=$PWD; S=$R/.gpu-stage-cpu; OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
L="$S/lib/ld-linux-x86-64.so.2"
row() {  # row BUILD THREADS CASES STEPS
  local text
  text=$(cd /tmp && GEM_SCENARIOS=$R/scenarios GEM_CPU_TIMING=1 $L --library-path $S/$1:$S/lib $S/$1/gem bench --backend cpu --cases "$3" --steps "$4" --threads "$2" 2>&1)
  echo "$1 threads $2: $(echo "$text" | grep -E '^(10\^5|824) ' | sed 's/  */ /g' | awk '{for (i = 1; i <= NF; ++i) if ($i == "variable_radius") print $(i + 2)}') ms"
  echo "$text" | grep '^gem cpu' | sed 's/^/  /'
}
for r in $(seq ${ROUNDS:-5}); do
  echo "round $r" >> "$OUT/devmachine-1e5.txt"
  order="base final"; [ $((r % 2)) = 0 ] && order="final base"
  for b in $order; do for t in 1 2; do row $b $t 100000 60000 >> "$OUT/devmachine-1e5.txt"; done; done
done
for r in $(seq ${ROUNDS_824:-6}); do
  echo "round $r" >> "$OUT/devmachine-824.txt"
  order="old base final"; [ $((r % 2)) = 0 ] && order="final base old"
  for b in $order; do row $b 1 824 4000 >> "$OUT/devmachine-824.txt"; done
done
