#!/usr/bin/env bash
# Issue "CPU speed" on the lent H200 machine's 16-core CPU: the build of 4b9a790 (after: the
# narrowphase's join, GEM_CPU_TIMING) against ea816c2 (before), alternated round by round.
# 10^5 floes on 16 threads and on one (pinned to a core), then 824 floes on one pinned core.
# Run from the stage folder (.gpu-stage-cpu: before/ and after/ each hold gem and libgem_core.so).
S=$(cd "$(dirname "$0")" && pwd)
OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
{ date -u; nproc; lscpu | grep "Model name"; uptime; } > "$OUT/machine.txt"
run() {  # build threads cases steps [pin]
  local b=$1 t=$2 c=$3 n=$4 pin=$5
  local pre=""; [ -n "$pin" ] && pre="taskset -c $pin"
  (cd /tmp && LD_LIBRARY_PATH=$S/$b:$S/lib GEM_SCENARIOS=$S/scenarios GEM_CPU_TIMING=1 timeout 120 $pre $S/$b/gem bench --backend cpu \
    --cases $c --steps $n --threads $t 2>&1) > /tmp/run.txt
  echo "$b threads $t $(grep -E '^(10\^5|824) ' /tmp/run.txt | head -1)" | tee -a "$OUT/rounds.txt"
  echo "$b threads $t cases $c: $(grep 'gem cpu timing' /tmp/run.txt | head -1)" >> "$OUT/phases.txt"
}
for r in 1 2 3 4 5 6 7; do
  echo "round $r" | tee -a "$OUT/rounds.txt"
  run after 16 100000 20000; run before 16 100000 20000
  run after 1 100000 20000 3; run before 1 100000 20000 3
done
for r in 1 2 3 4 5; do
  echo "824 round $r" | tee -a "$OUT/rounds.txt"
  run after 1 824 4000 5; run before 1 824 4000 5
done
uptime >> "$OUT/machine.txt"
