#!/usr/bin/env bash
# Round 2: the steady-state phases of the 10^5-floe step (GEM_CPU_TIMING=1, warm-up left out) on
# 1, 2, 4, 8 and 16 threads, three times, with the build of round 1 plus the bench's clock restart.
S=$(cd "$(dirname "$0")" && pwd)
OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
{ date -u; nproc; lscpu | grep "Model name"; uptime; } > "$OUT/machine2.txt"
for r in 1 2 3; do
  for t in 16 1 8 4 2; do
    pre=""; [ $t = 1 ] && pre="taskset -c 3"
    (cd /tmp && LD_LIBRARY_PATH=$S/after:$S/lib GEM_SCENARIOS=$S/scenarios GEM_CPU_TIMING=1 timeout 120 $pre $S/after/gem bench --backend cpu \
      --cases 100000 --steps 20000 --threads $t 2>&1) > /tmp/run.txt
    echo "round $r threads $t: $(grep -E '^10\^5 ' /tmp/run.txt | awk '{print $8}') ms; $(grep 'gem cpu timing' /tmp/run.txt)" | tee -a "$OUT/phases2.txt"
  done
done
uptime >> "$OUT/machine2.txt"
