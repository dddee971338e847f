#!/usr/bin/env bash
cd "$(dirname "$0")"
export GEM_BINARY_DIR=$PWD GEM_SOURCE_DIR=$PWD GEM_TEST_CUDA_PLUGIN_DIR=$PWD/cuda_plugins
for v in base var-pl16 var-pl8; do
  if [ $v = base ]; then export LD_LIBRARY_PATH=$PWD/lib; else export LD_LIBRARY_PATH=$PWD/$v:$PWD/lib; fi
  echo "== $v"
  GEM_CUDA_TIMING=1 GEM_CUDA_DRIVER=resident ./gem run scenarios/thesis/random_50.toml --backend cuda --out /tmp/r-$v --steps 2000 2>&1 | grep "resident driver" | tee $OUT/phases-$v.txt | cut -c1-330
  ./gem bench --table resident --sizes 1000 --csv $OUT/resident-$v.csv 2>&1 | grep -E "resident " | tail -4
done
echo "== tests with var-pl8 and var-pl16"
for v in var-pl8 var-pl16; do LD_LIBRARY_PATH=$PWD/$v:$PWD/lib ./gem_cuda_tests --gtest_filter='*Resident*:*Together*:*Ensemble*:WarpContact.*' 2>&1 | grep -E "^\[ +(FAILED|PASSED) " | tail -3; done
echo "== full CUDA suite (base)"
LD_LIBRARY_PATH=$PWD/lib ./gem_cuda_tests --gtest_color=no > $OUT/cuda-tests.txt 2>&1; echo "cuda tests rc=$?"
grep -E "^\[ +(FAILED|PASSED|SKIPPED) " $OUT/cuda-tests.txt | tail -5
