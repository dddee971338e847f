#!/usr/bin/env bash
# Issue "Trust" item 5, 2026-12-04 evening: does the memcheck report of the graph path on a shared
# GPU go away when no device or pinned address is ever handed out twice in the process
# (GEM_CUDA_KEEP_FREED=1: an experiment-only patch to framework/api/cuda_check.hpp, not on main;
# README.md says what it did)? A public report against another CUDA
# project's WHILE-loop graphs has compute-sanitizer fault on memory allocated shortly before the
# capture. Run in the folder scripts/stage-gpu.sh stages, with memcheck-loop.sh copied beside it.
#   CONTROL=N   runs of the default (one at a time, beside an unsanitized loop of the test)
#   KEEP=N AT_ONCE=K   runs with GEM_CUDA_KEEP_FREED=1, K at a time, beside the same loop
cd "$(dirname "$0")"; S=$PWD
export LD_LIBRARY_PATH=$PWD/lib GEM_BINARY_DIR=$PWD GEM_SOURCE_DIR=$PWD GEM_TEST_CUDA_PLUGIN_DIR=$PWD/cuda_plugins
OUT=${OUT:-/tmp/out}; mkdir -p $OUT
{ date -u; nvidia-smi --query-gpu=name,driver_version --format=csv; compute-sanitizer --version 2>/dev/null | tail -1; } >> $OUT/device.txt
san=$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)
T=CudaBroadphase.EveryStrategyGivesTheGridsTrajectoriesBitForBit
export GEM_CUDA_DRIVER=device
rm -f /tmp/stop-bg
( while [ ! -f /tmp/stop-bg ]; do ./gem_cuda_tests --gtest_filter=$T > /dev/null 2>&1; done ) &
sleep 4
for k in $(seq ${CONTROL:-0}); do
  w=$(mktemp -d)
  (cd $w && timeout 150 $san --tool memcheck --error-exitcode 9 $S/gem_cuda_tests --gtest_filter=$T > $OUT/control-$k.txt 2>&1
   echo "control $k rc=$? $(grep -h 'ERROR SUMMARY' $OUT/control-$k.txt | head -1)") | tee -a $OUT/summary.txt
done
if [ "${KEEP:-0}" -gt 0 ]; then
  GEM_CUDA_KEEP_FREED=1 bash ./memcheck-loop.sh $KEEP ${AT_ONCE:-4} /tmp/keep -- $PWD/gem_cuda_tests --gtest_filter=$T
  cp /tmp/keep/tally.txt $OUT/keep-tally-${TAG:-a}.txt; cp /tmp/keep/exit-codes.txt $OUT/keep-exit-codes-${TAG:-a}.txt
  bad=$(awk '$2 != 0 {print $1; exit}' /tmp/keep/exit-codes.txt); [ -n "$bad" ] && head -c 20000 /tmp/keep/run-$bad.txt > $OUT/keep-first-bad-${TAG:-a}.txt
  head -c 4000 /tmp/keep/run-1.txt > $OUT/keep-run-1-${TAG:-a}.txt
fi
touch /tmp/stop-bg; wait
cat $OUT/summary.txt $OUT/keep-tally-*.txt 2>/dev/null
