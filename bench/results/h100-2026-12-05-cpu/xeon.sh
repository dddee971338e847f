#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-05 evening: where 16 threads of the H200 machine's Xeon spend the
# 10^5-floe step, and the 824-floe field on one core against 4e89f89. Run from the repository root
# with .gpu-stage-cpu carried: old/ (4e89f89) and the builds named in BUILDS (gem and libgem_core.so
# of each, Release builds made on the development machine with -DGEM_DISABLE_CUDA=ON), lib/ (their
# libraries and the development machine's loader, so every build calls the same libm), perf.tar.xz
# (perf and its libraries) and stream (stream.cpp built). Writes under $OUT: machine.txt,
# stream.txt, scaling.txt, perf-16.txt, perf-16-threads.txt, rounds-824.txt,
# rounds-1e5.txt, table-cpu.txt and table-cpu.csv (TABLE=1).
R=$PWD; S=$R/.gpu-stage-cpu; OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
NEW=${NEW:-new}
{ date -u; nproc; lscpu; uptime; free -g; } > "$OUT/machine.txt" 2>&1
L="$S/lib/ld-linux-x86-64.so.2"
gem() {  # gem BUILD ARGS...: that build's gem through the carried loader and libraries ($PIN before it)
  local b=$1; shift
  (cd /tmp && GEM_SCENARIOS=$R/scenarios GEM_CPU_TIMING=1 $PIN $L --library-path $S/$b:$S/lib $S/$b/gem "$@")
}
row() {  # row BUILD THREADS CASES STEPS: one bench row (one thread pinned to core $CORE, default 3), one line
  local b=$1 t=$2 c=$3 n=$4 text
  if [ "$t" = 1 ]; then text=$(PIN="taskset -c ${CORE:-3}" gem "$b" bench --backend cpu --cases "$c" --steps "$n" --threads 1 2>&1)
  else text=$(PIN="" gem "$b" bench --backend cpu --cases "$c" --steps "$n" --threads "$t" 2>&1); fi
  echo "$b threads $t: $(echo "$text" | grep -E '^(10\^5|824) ' | sed 's/  */ /g' | awk '{for (i = 1; i <= NF; ++i) if ($i == "variable_radius") print $(i + 2)}') ms; $(echo "$text" | grep 'gem cpu timing' | sed 's/.*thread[s]*: //')"
}
$L --library-path $S/lib $S/stream 1 2 4 8 16 > "$OUT/stream.txt" 2>&1
if [ "${SCALING:-1}" = 1 ]; then
  for b in ${SCALING_BUILDS:-$BUILDS}; do for t in 1 2 4 8 16; do row $b $t 100000 60000 | tee -a "$OUT/scaling.txt"; done; done
fi
if [ "${PERF:-1}" = 1 ]; then
  mkdir -p /tmp/pf && tar xJf $S/perf.tar.xz -C /tmp/pf
  P="$L --library-path /tmp/pf/perf:$S/lib /tmp/pf/perf/perf"
  (cd /tmp && GEM_SCENARIOS=$R/scenarios $P record -F 2000 -o /tmp/perf16.data -- $L --library-path $S/$NEW:$S/lib $S/$NEW/gem bench --backend cpu --cases 100000 --steps 300000 --threads 16 > /dev/null 2>&1)
  $P report -i /tmp/perf16.data --no-children --sort sym --stdio 2>/dev/null | grep -v '^#' | grep -v '^$' | head -70 | cut -c1-220 > "$OUT/perf-16.txt"
  $P report -i /tmp/perf16.data --no-children --sort pid,sym --stdio 2>/dev/null | grep -v '^#' | grep -v '^$' | head -400 | cut -c1-220 > "$OUT/perf-16-threads.txt"
fi
for r in $(seq ${ROUNDS_824:-10}); do
  echo "round $r" >> "$OUT/rounds-824.txt"
  builds=${ORDER_824:-old $NEW}
  if [ $((r % 2)) = 1 ]; then order=$builds; else order=$(echo $builds | tr ' ' '\n' | tac | tr '\n' ' '); fi
  for b in $order; do row $b 1 824 4000 | tee -a "$OUT/rounds-824.txt"; done
done
for r in $(seq ${ROUNDS_1E5:-3}); do
  echo "round $r" >> "$OUT/rounds-1e5.txt"
  for t in 1 16; do for b in $BUILDS; do row $b $t 100000 60000 | tee -a "$OUT/rounds-1e5.txt"; done; done
done
[ "${TABLE:-0}" = 1 ] && PIN="" gem $NEW bench --table cpu --steps 60000 --csv "$OUT/table-cpu.csv" > "$OUT/table-cpu.txt" 2>&1
uptime >> "$OUT/machine.txt"
