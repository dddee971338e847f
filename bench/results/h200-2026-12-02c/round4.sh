#!/usr/bin/env bash
# Round 4: the CUDA suite at this commit, then the CPU side by side on the H200 machine's CPU:
# 824 floes on one pinned core (4e89f89 = base, c070616 = headref, this build = new), six rounds
# alternated; then 10^5 floes at 1 and 16 threads alternated, three rounds (new only).
cd "$(dirname "$0")"
D=$PWD
export LD_LIBRARY_PATH=$PWD/lib GEM_BINARY_DIR=$PWD GEM_SOURCE_DIR=$PWD GEM_TEST_CUDA_PLUGIN_DIR=$PWD/cuda_plugins
OUT=${OUT:-/tmp/out}; mkdir -p $OUT
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/device.txt; lscpu | grep -E "Model name|^CPU\(s\)" >> $OUT/device.txt
(timeout 220 ./gem_cuda_tests > $OUT/cuda-tests.txt 2>&1; echo "suite rc=$?"); tail -4 $OUT/cuda-tests.txt
for r in 1 2 3 4 5 6; do
  for v in base headref new; do
    if [ $v = new ]; then b=$D/gem; L=$D/lib; else b=$D/$v/gem; L=$D/$v:$D/lib; fi
    t=$(cd /tmp && LD_LIBRARY_PATH=$L GEM_SCENARIOS=$D/scenarios taskset -c 3 $b bench --backend cpu --cases 824 --steps 4000 --threads 1 2>&1 | grep "^824" | awk '{print $8}')
    echo "cpu824 round $r $v $t" | tee -a $OUT/cpu-824-side-by-side.txt
  done
done
for r in 1 2 3; do
  for t in 1 16; do
    (cd /tmp && GEM_SCENARIOS=$D/scenarios $D/gem bench --backend cpu --cases 100000 --steps 20000 --threads $t 2>&1 | grep "^10^5" | sed "s/^/$t /") | tee -a $OUT/cpu-10e5-threads-alternated.txt
  done
done
