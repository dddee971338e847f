#!/usr/bin/env bash
# Round 7: the CPU side by side once more, one build at a time on one pinned core (4e89f89 = base,
# this build = new, alternated ten times), then 10^5 floes at 1 and 16 threads alternated.
cd "$(dirname "$0")"
D=$PWD
export LD_LIBRARY_PATH=$PWD/lib
OUT=${OUT:-/tmp/out}; mkdir -p $OUT
lscpu | grep -E "Model name|^CPU\(s\)" > $OUT/device.txt
for r in 1 2 3 4 5 6 7 8 9 10; do
  for v in base new; do
    if [ $v = new ]; then b=$D/gem; L=$D/lib; else b=$D/$v/gem; L=$D/$v:$D/lib; fi
    t=$(cd /tmp && LD_LIBRARY_PATH=$L GEM_SCENARIOS=$D/scenarios taskset -c 3 $b bench --backend cpu --cases 824 --steps 4000 --threads 1 2>&1 | grep "^824" | awk '{print $8}')
    echo "cpu824 round $r $v core 3 $t" | tee -a $OUT/cpu-824-side-by-side.txt
  done
done
for r in 1 2 3; do
  for t in 1 16; do
    (cd /tmp && GEM_SCENARIOS=$D/scenarios $D/gem bench --backend cpu --cases 100000 --steps 20000 --threads $t 2>&1 | grep "^10^5" | sed "s/^/$t /") | tee -a $OUT/cpu-10e5-threads-alternated.txt
  done
done
