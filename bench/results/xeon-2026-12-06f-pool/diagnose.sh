#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-06 night: where 10^5 floes on 1 to 16 threads of the lent machine's
# Xeon spend their step, with the pool's own account (GEM_CPU_TIMING=1 prints "gem cpu pool":
# rounds, tasks, the time waiting on the last tasks, the calling thread's time between rounds), and
# the 824-floe field on one core, old (4e89f89) against the builds in BUILDS, alternated. Run from
# the repository root with .gpu-stage-cpu carried (../h100-2026-12-05-cpu/xeon.sh says what it
# holds); writes under $OUT.
R=$PWD; S=$R/.gpu-stage-cpu; OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
BUILDS=${BUILDS:-pool}
{ date -u; nproc; lscpu | head -20; uptime; } > "$OUT/machine.txt" 2>&1
L="$S/lib/ld-linux-x86-64.so.2"
gem() {  # gem BUILD ARGS...: that build's gem through the carried loader and libraries ($PIN before it)
  local b=$1; shift
  (cd /tmp && GEM_SCENARIOS=$R/scenarios GEM_CPU_TIMING=${TIMING:-1} $PIN $L --library-path $S/$b:$S/lib $S/$b/gem "$@")
}
row() {  # row BUILD THREADS CASES STEPS: the bench's ms a step, then the timing lines
  local b=$1 t=$2 c=$3 n=$4 text pin=""
  [ "$t" = 1 ] && pin="taskset -c ${CORE:-3}"
  text=$(PIN="$pin" gem "$b" bench --backend cpu --cases "$c" --steps "$n" --threads "$t" 2>&1)
  echo "$b threads $t: $(echo "$text" | grep -E '^(10\^5|824) ' | sed 's/  */ /g' | awk '{for (i = 1; i <= NF; ++i) if ($i == "variable_radius") print $(i + 2)}') ms"
  echo "$text" | grep '^gem cpu' | sed 's/^/  /'
}
for b in $BUILDS; do for t in ${THREADS-1 2 4 8 16}; do row $b $t 100000 60000 | tee -a "$OUT/scaling.txt"; done; done
for r in $(seq ${ROUNDS_824:-6}); do
  echo "round $r" >> "$OUT/rounds-824.txt"
  order="old $BUILDS"; [ $((r % 2)) = 0 ] && order=$(echo $order | tr ' ' '\n' | tac | tr '\n' ' ')
  for b in $order; do TIMING=0 row $b 1 824 4000 | tee -a "$OUT/rounds-824.txt"; done
done
uptime >> "$OUT/machine.txt"
