#!/usr/bin/env bash
cd "$(dirname "$0")"
export LD_LIBRARY_PATH=$PWD/lib GEM_BINARY_DIR=$PWD GEM_SOURCE_DIR=$PWD GEM_TEST_CUDA_PLUGIN_DIR=$PWD/cuda_plugins
san=$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)
T=CudaBroadphase.EveryStrategyGivesTheGridsTrajectoriesBitForBit
export GEM_CUDA_DRIVER=device
rm -f /tmp/stop-bg
( while [ ! -f /tmp/stop-bg ]; do ./gem_cuda_tests --gtest_filter=$T > /dev/null 2>&1; done ) &
sleep 4
one() { name=$1; shift; for k in $(seq $RUNS); do w=$(mktemp -d); (cd $w && timeout 150 "$@" > $OUT/mc-$name-$k.txt 2>&1; echo "$name $k rc=$? $(grep -h 'ERROR SUMMARY' $OUT/mc-$name-$k.txt | head -1)"); done; }
for mode in upload memset realloc big kernels cub upload-memset-realloc-big-kernels-cub; do RUNS=2 one gg-$mode env GEM_MEMCHECK_GEMGRAPH=$mode $san --tool memcheck --error-exitcode 9 $PWD/gem_cuda_tests --gtest_filter=MemcheckProbe.GemShaped*; done
touch /tmp/stop-bg; wait
