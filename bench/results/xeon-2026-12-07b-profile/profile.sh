#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-07 (session 28): where the 824-floe step spends its time on the lent
# machine's Xeon, whose narrowphase takes twice the AMD core's time (performance.md 3.20).
# perf and its libraries travel in .gpu-stage-cpu/perf (Debian 12's linux-perf), the build under
# test in .gpu-stage-cpu/$BUILD, 4e89f89 in .gpu-stage-cpu/old. Run from the repository root;
# writes under $OUT: machine.txt, stat.txt (hardware counters where the VM exposes them),
# samples-BUILD.txt (perf script: address, symbol, object of every sample, gzipped) and
# report-BUILD.txt (perf report by symbol).
R=$PWD; S=$R/.gpu-stage-cpu; OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
BUILD=${BUILD:-s39}
L="$S/lib/ld-linux-x86-64.so.2"
{ date -u; nproc; lscpu | head -24; uptime; cat /proc/sys/kernel/perf_event_paranoid; } > "$OUT/machine.txt" 2>&1
perf() { $L --library-path $S/perf:$S/lib $S/perf/perf "$@"; }
gemcmd() { echo "taskset -c ${CORE:-3} $L --library-path $S/$1:$S/lib $S/$1/gem bench --backend cpu --cases 824 --threads 1 --steps ${STEPS:-4000}"; }
cd /tmp
export GEM_SCENARIOS=$R/scenarios
for b in old $BUILD old $BUILD; do
  echo "== $b" >> "$OUT/stat.txt"
  perf stat -e task-clock,cycles,instructions,branches,branch-misses,L1-dcache-load-misses,LLC-load-misses $(gemcmd $b) >> "$OUT/stat.txt" 2>&1
done
perf stat -M TopdownL1 $(gemcmd $BUILD) >> "$OUT/stat.txt" 2>&1 || true
for b in $BUILD old; do
  perf record -F 9999 -o /tmp/p-$b.data $(gemcmd $b) > "$OUT/record-$b.log" 2>&1
  perf report -i /tmp/p-$b.data --stdio --no-children --sort dso,sym 2>&1 | head -80 > "$OUT/report-$b.txt"
  perf script -i /tmp/p-$b.data -F event,ip,sym,dso 2>/dev/null | gzip > "$OUT/samples-$b.txt.gz"
done
uptime >> "$OUT/machine.txt"
