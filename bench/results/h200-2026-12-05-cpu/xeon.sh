#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-05: the CPU step with the body updates run block by block and the
# re-sort into kept arrays (new, debc1f9) against the step before them (base, fd5fe03) and the main
# the issue measured against (old, 4e89f89), on the H200 machine's Xeon. Run from the repository
# root with .gpu-stage-cpu carried: old/, base/, new/ (gem and libgem_core.so of each, Release
# builds made on the development machine with -DGEM_DISABLE_CUDA=ON) and lib/ (their libraries and
# the development machine's loader, so every build calls the same libm). Writes under $OUT:
# machine.txt, rounds-824.txt, rounds-1e5.txt, table-cpu.txt and table-cpu.csv.
R=$PWD; S=$R/.gpu-stage-cpu; OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
{ date -u; nproc; lscpu | grep -E "Model name|^CPU\(s\)|Thread|MHz"; uptime; } > "$OUT/machine.txt" 2>&1
gem() {  # gem BUILD ARGS...: that build's gem through the carried loader and libraries ($PIN before it)
  local b=$1; shift
  (cd /tmp && GEM_SCENARIOS=$R/scenarios GEM_CPU_TIMING=1 $PIN $S/lib/ld-linux-x86-64.so.2 --library-path $S/$b:$S/lib $S/$b/gem "$@")
}
row() {  # row BUILD THREADS CASES STEPS: one bench row (one thread pinned to core 3), one line
  local b=$1 t=$2 c=$3 n=$4 text
  if [ "$t" = 1 ]; then text=$(PIN="taskset -c 3" gem "$b" bench --backend cpu --cases "$c" --steps "$n" --threads 1 2>&1)
  else text=$(PIN="" gem "$b" bench --backend cpu --cases "$c" --steps "$n" --threads "$t" 2>&1); fi
  echo "$b threads $t: $(echo "$text" | grep -E '^(10\^5|824) ' | sed 's/  */ /g' | awk '{for (i = 1; i <= NF; ++i) if ($i == "variable_radius") print $(i + 2)}') ms; $(echo "$text" | grep 'gem cpu timing' | sed 's/.*thread[s]*: //')"
}
for r in $(seq ${ROUNDS_824:-10}); do  # ORDER_824 overrides the builds (e.g. "old new")
  echo "round $r" >> "$OUT/rounds-824.txt"
  builds=${ORDER_824:-old base new}
  if [ $((r % 2)) = 1 ]; then order=$builds; else order=$(echo $builds | tr ' ' '\n' | tac | tr '\n' ' '); fi
  for b in $order; do row $b 1 824 4000 | tee -a "$OUT/rounds-824.txt"; done
done
for r in $(seq ${ROUNDS_1E5:-4}); do
  echo "round $r" >> "$OUT/rounds-1e5.txt"
  for t in 1 16; do for b in ${BUILDS_1E5:-base new}; do row $b $t 100000 60000 | tee -a "$OUT/rounds-1e5.txt"; done; done
done
[ "${TABLE:-1}" = 1 ] && PIN="" gem new bench --table cpu --steps 20000 --csv "$OUT/table-cpu.csv" > "$OUT/table-cpu.txt" 2>&1
uptime >> "$OUT/machine.txt"
