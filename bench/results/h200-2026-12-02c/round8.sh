#!/usr/bin/env bash
# Round 8: 10^5 floes on 16 threads, this build (new) and c070616 (headref) alternated, and one
# thread of each; uptime first and last, to see the shared machine's load.
cd "$(dirname "$0")"
D=$PWD
OUT=${OUT:-/tmp/out}; mkdir -p $OUT
uptime | tee -a $OUT/cpu-10e5-16-threads.txt
for r in 1 2 3; do
  for v in new headref; do
    if [ $v = new ]; then b=$D/gem; L=$D/lib; else b=$D/$v/gem; L=$D/$v:$D/lib; fi
    for t in 16; do
      (cd /tmp && LD_LIBRARY_PATH=$L GEM_SCENARIOS=$D/scenarios $b bench --backend cpu --cases 100000 --steps 20000 --threads $t 2>&1 | grep "^10^5" | sed "s/^/$v $t /") | tee -a $OUT/cpu-10e5-16-threads.txt
    done
  done
done
for v in new headref; do
  if [ $v = new ]; then b=$D/gem; L=$D/lib; else b=$D/$v/gem; L=$D/$v:$D/lib; fi
  (cd /tmp && LD_LIBRARY_PATH=$L GEM_SCENARIOS=$D/scenarios $b bench --backend cpu --cases 100000 --steps 20000 --threads 1 2>&1 | grep "^10^5" | sed "s/^/$v 1 /") | tee -a $OUT/cpu-10e5-16-threads.txt
done
uptime | tee -a $OUT/cpu-10e5-16-threads.txt
