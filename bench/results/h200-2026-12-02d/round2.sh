#!/usr/bin/env bash
# Round 2 (same day): more memcheck runs of the chained graph beside another GPU process (to pass
# 50 in a row with round 1's 30), then the WHILE and chain forms' speed side by side, then the
# CPU's 10^5 floes on 1 and 16 threads (issue "CPU speed").
cd "$(dirname "$0")"
export LD_LIBRARY_PATH=$PWD/lib GEM_BINARY_DIR=$PWD GEM_SOURCE_DIR=$PWD GEM_TEST_CUDA_PLUGIN_DIR=$PWD/cuda_plugins
OUT=${OUT:-/tmp/out}; mkdir -p $OUT
{ date -u; nvidia-smi --query-gpu=name,driver_version --format=csv; } > $OUT/device.txt
T=CudaBroadphase.EveryStrategyGivesTheGridsTrajectoriesBitForBit
rm -f /tmp/stop-bg
( while [ ! -f /tmp/stop-bg ]; do GEM_CUDA_DRIVER=device ./gem_cuda_tests --gtest_filter=$T > /dev/null 2>&1; done ) &
sleep 4
GEM_CUDA_DRIVER=device timeout ${LOOP_LIMIT:-330} bash ./memcheck-loop.sh ${CHAIN_LOOP_RUNS:-21} ${AT_ONCE:-3} $OUT/chain-loop -- $PWD/gem_cuda_tests --gtest_filter=$T
rm -rf $OUT/chain-loop/work-*
touch /tmp/stop-bg; wait
for r in 1 2; do
  for form in while chain; do
    for n in 456 824; do
      t=$(cd /tmp && GEM_CUDA_GRAPH_LOOP=$form GEM_SCENARIOS=$GEM_SOURCE_DIR/scenarios timeout 60 $GEM_BINARY_DIR/gem bench --backend cuda --cases $n --steps 4000 2>&1 | grep "^$n" | head -1)
      echo "round $r $form $t" | tee -a $OUT/bench-while-chain.txt
    done
  done
done
for r in 1 2; do
  for t in 16 1; do
    line=$(cd /tmp && GEM_SCENARIOS=$GEM_SOURCE_DIR/scenarios timeout 60 $GEM_BINARY_DIR/gem bench --backend cpu --cases 100000 --steps 20000 --threads $t 2>&1 | grep "^100000" | head -1)
    echo "round $r threads $t $line" | tee -a $OUT/cpu-10e5-threads.txt
  done
done
