#!/usr/bin/env bash
# Round 1 of 2026-12-02 (session 8): the CUDA suite, then the template fix against the old
# behaviour under memcheck beside another GPU process, then the CPU 824-floe side by side.
cd "$(dirname "$0")"
export LD_LIBRARY_PATH=$PWD/lib GEM_BINARY_DIR=$PWD GEM_SOURCE_DIR=$PWD GEM_TEST_CUDA_PLUGIN_DIR=$PWD/cuda_plugins
OUT=${OUT:-/tmp/out}; mkdir -p $OUT
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/device.txt
san=$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)
T=CudaBroadphase.EveryStrategyGivesTheGridsTrajectoriesBitForBit
mc="$san --tool memcheck --error-exitcode 9"
if [ "${SKIP_SUITE:-0}" != 1 ]; then
  (timeout 200 ./gem_cuda_tests > $OUT/cuda-tests.txt 2>&1; echo "suite rc=$?") | tee -a $OUT/summary.txt
  tail -3 $OUT/cuda-tests.txt
fi
one() {  # NAME COMMAND...: RUNS runs, each in a fresh folder
  name=$1; shift
  for k in $(seq $RUNS); do
    w=$(mktemp -d)
    (cd $w && timeout 150 "$@" > $OUT/mc-$name-$k.txt 2>&1; echo "$name $k rc=$? illegal=$(grep -c cudaErrorIllegalAddress $OUT/mc-$name-$k.txt) $(grep -h 'ERROR SUMMARY' $OUT/mc-$name-$k.txt | head -1)") | tee -a $OUT/summary.txt
  done
}
rm -f /tmp/stop-bg
( while [ ! -f /tmp/stop-bg ]; do GEM_CUDA_DRIVER=device ./gem_cuda_tests --gtest_filter=$T > /dev/null 2>&1; done ) &
sleep 4
export GEM_CUDA_DRIVER=device
RUNS=${CONTROL_RUNS:-3} one old-drop-template env GEM_EXPERIMENT_DROP_TEMPLATE=1 $mc $PWD/gem_cuda_tests --gtest_filter=$T
RUNS=${FIX_RUNS:-5} one kept-template $mc $PWD/gem_cuda_tests --gtest_filter=$T
touch /tmp/stop-bg; wait
unset GEM_CUDA_DRIVER
# CPU: 824 floes on one pinned core, 4e89f89 (base), c070616 (headref) and this build alternated.
if [ "${SKIP_CPU:-0}" != 1 ]; then
  for r in 1 2 3 4; do
    for v in base headref new; do
      if [ $v = new ]; then b=./gem; L=$PWD/lib; else b=$PWD/$v/gem; L=$PWD/$v:$PWD/lib; fi
      t=$(cd /tmp && LD_LIBRARY_PATH=$L GEM_SCENARIOS=$GEM_SOURCE_DIR/scenarios taskset -c 3 $b bench --backend cpu --cases 824 --steps 4000 --threads 1 2>&1 | grep "^824" | awk '{print $8}')
      echo "cpu824 round $r $v $t" | tee -a $OUT/cpu-824-side-by-side.txt
    done
  done
fi
