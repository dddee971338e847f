#!/usr/bin/env bash
# Round 3: the build of 9d86730 (after: the re-sort on the pool, the vessel's slot remembered; the
# phase clock) against ea816c2 (before), 10^5 floes on 16 threads and on one (pinned), alternated.
S=$(cd "$(dirname "$0")" && pwd)
OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
{ date -u; nproc; lscpu | grep "Model name"; uptime; } > "$OUT/machine3.txt"
for r in 1 2 3 4 5 6; do
  for b in after before; do
    for t in 16 1; do
      pre=""; [ $t = 1 ] && pre="taskset -c 3"
      (cd /tmp && LD_LIBRARY_PATH=$S/$b:$S/lib GEM_SCENARIOS=$S/scenarios GEM_CPU_TIMING=1 timeout 120 $pre $S/$b/gem bench --backend cpu \
        --cases 100000 --steps 20000 --threads $t 2>&1) > /tmp/run.txt
      echo "round $r $b threads $t: $(grep -E '^10\^5 ' /tmp/run.txt | awk '{print $8}') ms; $(grep 'gem cpu timing' /tmp/run.txt)" | tee -a "$OUT/rounds3.txt"
    done
  done
done
uptime >> "$OUT/machine3.txt"
