#!/usr/bin/env bash
# Round 3: where the fault surfaces (experiment-only labelled device syncs in DeviceStep::run,
# GEM_EXPERIMENT_SYNCS), two memcheck options, beside another GPU process; then the CPU 824-floe
# side by side (4e89f89 = base, c070616 = headref, this build = new), pinned to one core.
cd "$(dirname "$0")"
D=$PWD
export LD_LIBRARY_PATH=$PWD/lib GEM_BINARY_DIR=$PWD GEM_SOURCE_DIR=$PWD GEM_TEST_CUDA_PLUGIN_DIR=$PWD/cuda_plugins
OUT=${OUT:-/tmp/out}; mkdir -p $OUT
san=$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)
T=CudaBroadphase.EveryStrategyGivesTheGridsTrajectoriesBitForBit
one() {  # NAME COMMAND...: RUNS runs, each in a fresh folder
  name=$1; shift
  for k in $(seq $RUNS); do
    w=$(mktemp -d)
    (cd $w && timeout 150 "$@" > $OUT/mc-$name-$k.txt 2>&1; echo "$name $k rc=$? illegal=$(grep -c cudaErrorIllegalAddress $OUT/mc-$name-$k.txt) $(grep -h 'ERROR SUMMARY' $OUT/mc-$name-$k.txt | head -1) | $(grep -h '\[syncs\]' $OUT/mc-$name-$k.txt | grep -v cudaSuccess | head -2 | tr '\n' ' ')") | tee -a $OUT/summary.txt
  done
}
export GEM_CUDA_DRIVER=device
rm -f /tmp/stop-bg
( while [ ! -f /tmp/stop-bg ]; do ./gem_cuda_tests --gtest_filter=$T > /dev/null 2>&1; done ) 2>/dev/null &
sleep 4
RUNS=3 one syncs env GEM_EXPERIMENT_SYNCS=1 $san --tool memcheck --error-exitcode 9 $D/gem_cuda_tests --gtest_filter=$T
RUNS=2 one no-api-check $san --tool memcheck --check-api-memory-access no --error-exitcode 9 $D/gem_cuda_tests --gtest_filter=$T
RUNS=2 one no-device-heap $san --tool memcheck --check-device-heap no --error-exitcode 9 $D/gem_cuda_tests --gtest_filter=$T
touch /tmp/stop-bg; wait
unset GEM_CUDA_DRIVER
for r in 1 2 3 4; do
  for v in base headref new; do
    if [ $v = new ]; then b=$D/gem; L=$D/lib; else b=$D/$v/gem; L=$D/$v:$D/lib; fi
    t=$(cd /tmp && LD_LIBRARY_PATH=$L GEM_SCENARIOS=$D/scenarios taskset -c 3 $b bench --backend cpu --cases 824 --steps 4000 --threads 1 2>&1 | grep "^824" | awk '{print $8}')
    echo "cpu824 round $r $v $t" | tee -a $OUT/cpu-824-side-by-side.txt
  done
done
