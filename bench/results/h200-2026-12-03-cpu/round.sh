#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-03: the CPU backend of main (head) against 4e89f89 (before, the issue's
# "main today") side by side on the H200 machine's CPU, alternated run by run: the 824-floe and the
# 456-hexagon fields on one pinned core, then head's 10^5-floe field on 16 threads and on one.
# Run from the repository root with .gpu-stage-cpu carried: head/ and before/ (gem and
# libgem_core.so of each build, made on the development machine) and lib/ (their other libraries).
R=$PWD
OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
{ date -u; nproc; lscpu | grep "Model name"; uptime; } > "$OUT/machine.txt" 2>&1
run() {  # build threads cases steps
  local b=$1 t=$2 c=$3 n=$4 pre=""
  [ "$t" = 1 ] && pre="taskset -c 3"
  (cd /tmp && LD_LIBRARY_PATH=$R/.gpu-stage-cpu/$b:$R/.gpu-stage-cpu/lib GEM_SCENARIOS=$R/scenarios GEM_CPU_TIMING=1 timeout 120 \
    $pre $R/.gpu-stage-cpu/$b/gem bench --backend cpu --cases $c --steps $n --threads $t 2>&1) > /tmp/run.txt
  echo "$b threads $t cases $c: $(grep -E '^(10\^5|824|456) ' /tmp/run.txt | sed 's/  */ /g' | cut -d' ' -f8) ms; $(grep 'gem cpu timing' /tmp/run.txt)" | tee -a "$OUT/rounds.txt"
}
for r in 1 2 3 4 5 6 7 8; do
  echo "824 round $r" >> "$OUT/rounds.txt"
  if [ $((r % 2)) = 1 ]; then run before 1 824 4000; run head 1 824 4000; else run head 1 824 4000; run before 1 824 4000; fi
done
for r in 1 2 3 4; do
  echo "456 round $r" >> "$OUT/rounds.txt"
  run before 1 456 6000; run head 1 456 6000
done
for r in 1 2 3; do
  echo "10^5 round $r" >> "$OUT/rounds.txt"
  run head 16 100000 20000; run head 1 100000 20000
done
uptime >> "$OUT/machine.txt"
