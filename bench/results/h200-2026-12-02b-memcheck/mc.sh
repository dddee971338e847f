#!/usr/bin/env bash
# Issue 15: which change makes the graph path's concurrent memcheck report go away.
cd "$(dirname "$0")"
export LD_LIBRARY_PATH=$PWD/lib GEM_BINARY_DIR=$PWD GEM_SOURCE_DIR=$PWD GEM_TEST_CUDA_PLUGIN_DIR=$PWD/cuda_plugins
san=$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)
$san --version | tail -1
$san --help 2>&1 | grep -i -A6 "kernel-name-exclude" | head -12
T=CudaBroadphase.EveryStrategyGivesTheGridsTrajectoriesBitForBit
export GEM_CUDA_DRIVER=device
rm -f /tmp/stop-bg
( while [ ! -f /tmp/stop-bg ]; do ./gem_cuda_tests --gtest_filter=$T > /dev/null 2>&1; done ) &
sleep 4
one() { name=$1; shift; for k in $(seq $RUNS); do w=$(mktemp -d); (cd $w && timeout 150 "$@" > $OUT/mc-$name-$k.txt 2>&1; echo "$name $k rc=$? $(grep -h 'ERROR SUMMARY' $OUT/mc-$name-$k.txt)"); done; }
RUNS=2 one control $san --tool memcheck --error-exitcode 9 $PWD/gem_cuda_tests --gtest_filter=$T
RUNS=3 one probe-trig $san --tool memcheck --error-exitcode 9 $PWD/probe/probe2 8 trig
RUNS=3 one probe-module2 $san --tool memcheck --error-exitcode 9 $PWD/probe/probe2 8 module2
RUNS=3 one probe-trig-module2 $san --tool memcheck --error-exitcode 9 $PWD/probe/probe2 8 trigmodule2
RUNS=3 one upload env GEM_CUDA_GRAPH_UPLOAD=1 $san --tool memcheck --error-exitcode 9 $PWD/gem_cuda_tests --gtest_filter=$T
RUNS=3 one exclude-prepare $san --tool memcheck --error-exitcode 9 --kernel-name-exclude kns=prepare $PWD/gem_cuda_tests --gtest_filter=$T
touch /tmp/stop-bg; wait
grep -h -m3 -B2 -A8 "Program hit\|Invalid\|illegal" $OUT/mc-upload-1.txt | head -40
