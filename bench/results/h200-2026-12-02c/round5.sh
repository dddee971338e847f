#!/usr/bin/env bash
# Round 5: where a 10^5-floe step's time goes on 1, 4 and 16 threads (an instrumented build, not
# on main: phase clocks in CpuStepper::step and KeptListBroadphase::findCandidates).
cd "$(dirname "$0")"
D=$PWD
export LD_LIBRARY_PATH=$PWD/lib
OUT=${OUT:-/tmp/out}; mkdir -p $OUT
for t in 1 16 4 1 16; do
  echo "== threads $t" >> $OUT/phases-10e5.txt
  (cd /tmp && GEM_SCENARIOS=$D/scenarios $D/gem bench --backend cpu --cases 100000 --steps 20000 --threads $t 2>&1 | grep -E "^bp|^phase|^10\^5") >> $OUT/phases-10e5.txt
done
cat $OUT/phases-10e5.txt
