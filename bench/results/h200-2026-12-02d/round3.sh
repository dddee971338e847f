#!/usr/bin/env bash
# Round 3 (same day): the CPU's 10^5 floes on 16 threads and on one, alternated (issue "CPU speed").
cd "$(dirname "$0")"
S=$PWD
export LD_LIBRARY_PATH=$PWD/lib
OUT=${OUT:-/tmp/out}; mkdir -p $OUT
{ date -u; nproc; uptime; } > $OUT/machine.txt
for r in 1 2 3; do
  for t in 16 1; do
    line=$(cd /tmp && GEM_SCENARIOS=$S/scenarios timeout 80 $S/gem bench --backend cpu --cases 100000 --steps 20000 --threads $t 2>&1 | grep "^10^5" | head -1)
    echo "round $r threads $t $line" | tee -a $OUT/cpu-10e5-threads.txt
  done
done
uptime >> $OUT/machine.txt
