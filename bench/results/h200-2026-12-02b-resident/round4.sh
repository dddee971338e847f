#!/usr/bin/env bash
cd "$(dirname "$0")"
export GEM_BINARY_DIR=$PWD GEM_SOURCE_DIR=$PWD GEM_TEST_CUDA_PLUGIN_DIR=$PWD/cuda_plugins
for v in base var-mb2-b512; do
  if [ $v = base ]; then export LD_LIBRARY_PATH=$PWD/lib; else export LD_LIBRARY_PATH=$PWD/$v:$PWD/lib; fi
  echo "== $v"
  ./gem bench --table resident --sizes 100 1000 --csv $OUT/resident-$v.csv 2>&1 | grep -E "resident|worlds" | tail -8
  GEM_CUDA_TIMING=1 GEM_CUDA_DRIVER=resident ./gem run scenarios/thesis/random_50.toml --backend cuda --out /tmp/r-$v --steps 2000 2>&1 | grep "resident driver" | tee $OUT/phases-$v.txt | cut -c1-400
done
echo "== variant tests"
./gem_cuda_tests --gtest_filter='*Resident*:*Together*:*Ensemble*' 2>&1 | grep -E "^\[ +(FAILED|PASSED|OK) " | tail -12
