#!/usr/bin/env bash
cd "$(dirname "$0")"
export LD_LIBRARY_PATH=$PWD/lib GEM_BINARY_DIR=$PWD GEM_SOURCE_DIR=$PWD GEM_TEST_CUDA_PLUGIN_DIR=$PWD/cuda_plugins
san=$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)
$san --help 2>&1 | grep -E "^  --" | cut -c1-60 > $OUT/sanitizer-options.txt
T=CudaBroadphase.EveryStrategyGivesTheGridsTrajectoriesBitForBit
export GEM_CUDA_DRIVER=device
rm -f /tmp/stop-bg
( while [ ! -f /tmp/stop-bg ]; do ./gem_cuda_tests --gtest_filter=$T > /dev/null 2>&1; done ) &
sleep 4
one() { name=$1; shift; for k in $(seq $RUNS); do w=$(mktemp -d); (cd $w && timeout 150 "$@" > $OUT/mc-$name-$k.txt 2>&1; echo "$name $k rc=$? $(grep -h 'ERROR SUMMARY' $OUT/mc-$name-$k.txt) $(grep -c '^\[       OK' $OUT/mc-$name-$k.txt)"); done; }
for mode in none prepare empty empty1 tiny; do
  RUNS=2 one body-$mode env GEM_EXPERIMENT_BODY=$mode $san --tool memcheck --error-exitcode 9 $PWD/gem_cuda_tests --gtest_filter=$T
done
RUNS=2 one padding0 $san --tool memcheck --padding 0 --error-exitcode 9 $PWD/gem_cuda_tests --gtest_filter=$T
touch /tmp/stop-bg; wait
