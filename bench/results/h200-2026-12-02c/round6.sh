#!/usr/bin/env bash
# Round 6: the CUDA suite at this commit; the CPU side by side on the H200 machine's CPU, 824 floes
# on one pinned core each (4e89f89 = base, c070616 = headref, this build = new, run at the same time
# on three cores, rotated every round); 10^5 floes at 1 and 16 threads alternated; the cpu table.
cd "$(dirname "$0")"
D=$PWD
export LD_LIBRARY_PATH=$PWD/lib GEM_BINARY_DIR=$PWD GEM_SOURCE_DIR=$PWD GEM_TEST_CUDA_PLUGIN_DIR=$PWD/cuda_plugins
OUT=${OUT:-/tmp/out}; mkdir -p $OUT
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/device.txt; lscpu | grep -E "Model name|^CPU\(s\)" >> $OUT/device.txt
[ "${SKIP_SUITE:-0}" = 1 ] || { (timeout 220 ./gem_cuda_tests > $OUT/cuda-tests.txt 2>&1; echo "suite rc=$?"); tail -4 $OUT/cuda-tests.txt; }
cores=(3 7 11)
for r in 1 2 3 4 5 6 7 8 9; do
  i=0
  for v in base headref new; do
    c=${cores[$(( (i + r) % 3 ))]}; i=$((i + 1))
    if [ $v = new ]; then b=$D/gem; L=$D/lib; else b=$D/$v/gem; L=$D/$v:$D/lib; fi
    ( t=$(cd /tmp && LD_LIBRARY_PATH=$L GEM_SCENARIOS=$D/scenarios taskset -c $c $b bench --backend cpu --cases 824 --steps 4000 --threads 1 2>&1 | grep "^824" | awk '{print $8}')
      echo "cpu824 round $r $v core $c $t" >> $OUT/cpu-824-side-by-side.txt ) &
  done
  wait
done
sort -k3,3n -k4 $OUT/cpu-824-side-by-side.txt
for r in 1 2 3; do
  for t in 1 16; do
    (cd /tmp && GEM_SCENARIOS=$D/scenarios $D/gem bench --backend cpu --cases 100000 --steps 20000 --threads $t 2>&1 | grep "^10^5" | sed "s/^/$t /") | tee -a $OUT/cpu-10e5-threads-alternated.txt
  done
done
(cd /tmp && GEM_SCENARIOS=$D/scenarios timeout 200 $D/gem bench --table cpu --steps 20000 --csv $OUT/cpu.csv > $OUT/cpu-table.txt 2>&1); cat $OUT/cpu-table.txt | tail -25
