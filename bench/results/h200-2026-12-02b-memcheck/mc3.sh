#!/usr/bin/env bash
cd "$(dirname "$0")"
export LD_LIBRARY_PATH=$PWD/lib GEM_BINARY_DIR=$PWD GEM_SOURCE_DIR=$PWD GEM_TEST_CUDA_PLUGIN_DIR=$PWD/cuda_plugins
san=$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)
T=CudaBroadphase.EveryStrategyGivesTheGridsTrajectoriesBitForBit
one() { name=$1; shift; for k in $(seq $RUNS); do w=$(mktemp -d); (cd $w && timeout 150 "$@" > $OUT/mc-$name-$k.txt 2>&1; echo "$name $k rc=$? $(grep -h 'ERROR SUMMARY' $OUT/mc-$name-$k.txt | head -1)"); done; }
beside() {  # beside NAME OTHER-COMMAND...: run the sanitized T 3 times while OTHER loops
  name=$1; shift
  rm -f /tmp/stop-bg
  ( while [ ! -f /tmp/stop-bg ]; do "$@" > /dev/null 2>&1; done ) &
  sleep 4
  RUNS=3 one $name env GEM_CUDA_DRIVER=device $san --tool memcheck --error-exitcode 9 $PWD/gem_cuda_tests --gtest_filter=$T
  touch /tmp/stop-bg; wait
}
beside other-graph0 env GEM_CUDA_DRIVER=device GEM_CUDA_GRAPH=0 ./gem_cuda_tests --gtest_filter=$T
beside other-probe ./probe/probe2 64
beside other-resident env GEM_CUDA_DRIVER=resident ./gem_cuda_tests --gtest_filter='CudaBackend.Resident*:CudaBackend.*Together*'
RUNS=3 one alone-body-none env GEM_CUDA_DRIVER=device GEM_EXPERIMENT_BODY=none $san --tool memcheck --error-exitcode 9 $PWD/gem_cuda_tests --gtest_filter=$T
