#!/usr/bin/env bash
# Issue "Trust" item 5, 2026-12-05 (README.md beside this file): is the graph path's memcheck report on a shared GPU made by
# GEM's kernels or by the tool? Run in the folder scripts/stage-gpu.sh stages (memcheck-loop.sh and
# this script copied beside it). Every run is of the test the report comes from, with the graph
# path (GEM_CUDA_DRIVER=device), beside an unsanitized loop of the same test on the same GPU:
#   PLAIN=N    N runs with no sanitizer at all (does the graph path ever fault by itself?)
#   NONE=N     N runs under memcheck with no kernel instrumented (--kernel-name matches none)
#   NOAPI=N    N runs under memcheck, every kernel instrumented, API memory checks off
#   GEMONLY=N  N runs under memcheck with only GEM's kernels instrumented (--kernel-name kns=gem)
#   CUBONLY=N  N runs under memcheck with only CUB's kernels instrumented (--kernel-name kns=cub)
#   FULL=N     N runs under memcheck as usual (the control: expected to report)
#   ONLY="K:N ..."     N runs under memcheck with only the kernels whose names hold K instrumented
#   EXCEPT="K:N ..."   N runs under memcheck with every kernel instrumented but those holding K
#   ALONE=N    N runs under memcheck as usual, the loop beside stopped, through memcheck-loop.sh
#              one at a time (each waits for a GPU with no other process and says if one came)
cd "$(dirname "$0")"; S=$PWD
export LD_LIBRARY_PATH=$PWD/lib GEM_BINARY_DIR=$PWD GEM_SOURCE_DIR=$PWD GEM_TEST_CUDA_PLUGIN_DIR=$PWD/cuda_plugins
OUT=${OUT:-/tmp/out}; mkdir -p $OUT
san=$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)
{ date -u; nvidia-smi --query-gpu=name,driver_version --format=csv; $san --version 2>/dev/null | tail -1; } >> $OUT/device.txt
$san --help > $OUT/sanitizer-help.txt 2>&1
T=CudaBroadphase.EveryStrategyGivesTheGridsTrajectoriesBitForBit
export GEM_CUDA_DRIVER=device
sum=$OUT/summary.txt
one() {  # one() LABEL K ARGS... : one run in its own folder, its log kept only when it failed
  local label=$1 k=$2; shift 2
  local w; w=$(mktemp -d); local log=$w/log.txt
  local t0; t0=$(date +%s)
  (cd $w && timeout 200 "$@" > $log 2>&1); local rc=$?
  local secs=$(($(date +%s) - t0))
  local errs; errs=$(grep -h 'ERROR SUMMARY' $log | head -1)
  local ill; ill=$(grep -c 'cudaErrorIllegalAddress\|illegal memory access' $log)
  echo "$label $k rc=$rc seconds=$secs illegal-lines=$ill $errs" | tee -a $sum
  if [ $rc != 0 ] && [ ! -f $OUT/first-bad-$label.txt ]; then head -c 12000 $log > $OUT/first-bad-$label.txt; fi
  rm -rf $w
}
background() { rm -f /tmp/stop-bg; ( while [ ! -f /tmp/stop-bg ]; do ./gem_cuda_tests --gtest_filter=$T > /dev/null 2>&1; done ) & sleep 4; }
background
nvidia-smi --query-compute-apps=pid,name --format=csv > $OUT/apps-with-the-loop-beside.txt 2>&1
for k in $(seq ${PLAIN:-0}); do one plain $k $S/gem_cuda_tests --gtest_filter=$T; done
for k in $(seq ${NONE:-0}); do one none $k $san --tool memcheck --error-exitcode 9 --kernel-name kns=NoKernelHasThisName $S/gem_cuda_tests --gtest_filter=$T; done
for k in $(seq ${NOAPI:-0}); do one noapi $k $san --tool memcheck --error-exitcode 9 --check-api-memory-access no $S/gem_cuda_tests --gtest_filter=$T; done
for k in $(seq ${GEMONLY:-0}); do one gemonly $k $san --tool memcheck --error-exitcode 9 --kernel-name kns=gem $S/gem_cuda_tests --gtest_filter=$T; done
for k in $(seq ${CUBONLY:-0}); do one cubonly $k $san --tool memcheck --error-exitcode 9 --kernel-name kns=cub $S/gem_cuda_tests --gtest_filter=$T; done
for spec in ${ONLY:-}; do for k in $(seq ${spec#*:}); do one "only-${spec%%:*}" $k $san --tool memcheck --error-exitcode 9 --kernel-name kns=${spec%%:*} $S/gem_cuda_tests --gtest_filter=$T; done; done
for spec in ${EXCEPT:-}; do for k in $(seq ${spec#*:}); do one "except-${spec%%:*}" $k $san --tool memcheck --error-exitcode 9 --kernel-name-exclude kns=${spec%%:*} $S/gem_cuda_tests --gtest_filter=$T; done; done
for k in $(seq ${FULL:-0}); do one full $k $san --tool memcheck --error-exitcode 9 $S/gem_cuda_tests --gtest_filter=$T; done
touch /tmp/stop-bg; wait
if [ "${ALONE:-0}" -gt 0 ]; then
  timeout ${ALONE_LIMIT:-100000} bash ./memcheck-loop.sh $ALONE 1 /tmp/alone -- $S/gem_cuda_tests --gtest_filter=$T
  cp /tmp/alone/tally.txt $OUT/alone-tally.txt 2>/dev/null; cp /tmp/alone/exit-codes.txt $OUT/alone-exit-codes.txt
  for f in /tmp/alone/run-*.txt; do echo "$(basename $f .txt) $(grep -h 'ERROR SUMMARY' $f)"; done > $OUT/alone-runs.txt
  cat /tmp/alone/company-*.txt > $OUT/alone-company.txt 2>/dev/null
fi
echo "== tally (label: runs, failed)"; awk '{n[$1]++; if ($3 != "rc=0") b[$1]++} END {for (l in n) print l": "n[l]" runs, "b[l]+0" failed"}' $sum | tee $OUT/tally.txt
