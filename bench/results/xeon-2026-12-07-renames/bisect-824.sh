#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-07 (session 27): which of the day's commits moved the 824-floe step on
# the lent Xeon. The builds in BUILDS (CPU-only Release builds of the development machine, run
# through the carried loader and libraries of .gpu-stage-cpu/, see ../h100-2026-12-05-cpu/xeon.sh)
# and old (4e89f89) on one pinned core, ROUNDS (12) alternated rounds (reversed every other round);
# then PHASE_ROUNDS (3) alternated rounds of PHASE_BUILDS with GEM_CPU_TIMING=1 (the phases of the
# step). Run from the repository root with .gpu-stage-cpu carried; writes under $OUT.
R=$PWD; S=$R/.gpu-stage-cpu; OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
BUILDS=${BUILDS:-s27 x-56d6949 x-8cb23f1 x-b236aba s36}
PHASE_BUILDS=${PHASE_BUILDS:-s27 s36}
{ date -u; nproc; lscpu | grep -E 'Model name|^CPU\(s\)'; uptime; } > "$OUT/machine.txt" 2>&1
L="$S/lib/ld-linux-x86-64.so.2"
gem() {  # gem BUILD ARGS...: that build's gem on core CORE (3)
  local b=$1; shift
  (cd /tmp && GEM_SCENARIOS=$R/scenarios GEM_CPU_TIMING=${TIMING:-0} taskset -c ${CORE:-3} $L --library-path $S/$b:$S/lib $S/$b/gem "$@")
}
row() {  # row BUILD: the 824-floe bench's ms a step (and the timing lines when TIMING=1)
  local text
  text=$(gem "$1" bench --backend cpu --cases 824 --steps 4000 --threads 1 2>&1)
  echo "$1 threads 1: $(echo "$text" | grep -E '^824 ' | sed 's/  */ /g' | awk '{for (i = 1; i <= NF; ++i) if ($i == "variable_radius") print $(i + 2)}') ms"
  echo "$text" | grep '^gem cpu' | sed 's/^/  /'
}
for r in $(seq ${ROUNDS:-12}); do
  echo "round $r" >> "$OUT/rounds-824.txt"
  order="old $BUILDS"; [ $((r % 2)) = 0 ] && order=$(echo $order | tr ' ' '\n' | tac | tr '\n' ' ')
  for b in $order; do row $b | tee -a "$OUT/rounds-824.txt"; done
done
for r in $(seq ${PHASE_ROUNDS:-3}); do
  order="$PHASE_BUILDS"; [ $((r % 2)) = 0 ] && order=$(echo $order | tr ' ' '\n' | tac | tr '\n' ' ')
  for b in $order; do TIMING=1 row $b | tee -a "$OUT/phases-824.txt"; done
done
uptime >> "$OUT/machine.txt"
