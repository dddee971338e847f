#!/usr/bin/env bash
# Round 1 of 2026-12-02 (session 9), in the staged folder: the CUDA suite with the chained batch
# graph (the new default), then memcheck of the graph path beside another GPU process, the old
# WHILE form first (the control), then the chain; then the two forms' speed side by side.
cd "$(dirname "$0")"
export LD_LIBRARY_PATH=$PWD/lib GEM_BINARY_DIR=$PWD GEM_SOURCE_DIR=$PWD GEM_TEST_CUDA_PLUGIN_DIR=$PWD/cuda_plugins
OUT=${OUT:-/tmp/out}; mkdir -p $OUT
{ date -u; nvidia-smi --query-gpu=name,driver_version --format=csv; } > $OUT/device.txt
san=$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)
T=CudaBroadphase.EveryStrategyGivesTheGridsTrajectoriesBitForBit
mc="$san --tool memcheck --error-exitcode 9"
if [ "${SKIP_SUITE:-0}" != 1 ]; then
  (timeout 200 ./gem_cuda_tests > $OUT/cuda-tests.txt 2>&1; echo "suite (chain) rc=$?") | tee -a $OUT/summary.txt
  tail -3 $OUT/cuda-tests.txt
fi
one() {  # NAME COMMAND...: RUNS runs, each in a fresh folder
  name=$1; shift
  for k in $(seq $RUNS); do
    w=$(mktemp -d)
    (cd $w && timeout 150 "$@" > $OUT/mc-$name-$k.txt 2>&1; echo "$name $k rc=$? $(grep -h 'ERROR SUMMARY' $OUT/mc-$name-$k.txt | head -1)") | tee -a $OUT/summary.txt
  done
}
rm -f /tmp/stop-bg
( while [ ! -f /tmp/stop-bg ]; do GEM_CUDA_DRIVER=device ./gem_cuda_tests --gtest_filter=$T > /dev/null 2>&1; done ) &
sleep 4
export GEM_CUDA_DRIVER=device
RUNS=${CONTROL_RUNS:-3} one while env GEM_CUDA_GRAPH_LOOP=while $mc $PWD/gem_cuda_tests --gtest_filter=$T
if [ "${CHAIN_LOOP_RUNS:-0}" -gt 0 ]; then
  # Many at once: the GPU shared by sanitized runs as well as by the unsanitized loop.
  bash ./memcheck-loop.sh $CHAIN_LOOP_RUNS ${AT_ONCE:-3} $OUT/chain-loop -- $PWD/gem_cuda_tests --gtest_filter=$T
  rm -rf $OUT/chain-loop/work-*
  ls $OUT/chain-loop | grep run- | head -3 | while read f; do :; done
else
  RUNS=${CHAIN_RUNS:-5} one chain $mc $PWD/gem_cuda_tests --gtest_filter=$T
fi
touch /tmp/stop-bg; wait
unset GEM_CUDA_DRIVER
if [ "${SKIP_BENCH:-0}" != 1 ]; then
  for r in 1 2 3; do
    for form in while chain; do
      for n in 456 824; do
        t=$(cd /tmp && GEM_CUDA_GRAPH_LOOP=$form GEM_SCENARIOS=$GEM_SOURCE_DIR/scenarios $GEM_BINARY_DIR/gem bench --backend cuda --cases $n --steps 4000 2>&1 | grep "^$n" | head -1)
        echo "round $r $form $t" | tee -a $OUT/bench-while-chain.txt
      done
    done
  done
fi
