#!/usr/bin/env bash
# The memcheck rounds of 2026-12-02 (README.md), as they ran from the staged build (.gpu-stage/):
#   bash rounds.sh ROUND     ROUND = 1 .. 7
# Each sanitized run goes beside an unsanitized loop of T on the same GPU (round 3 varies that
# loop). The probes: scripts/memcheck/while_graph_probe.cu (built as probe/probe2, probe/probe3,
# probe/probe3-shared with -cudart shared, probe/probe3-gemlinked linked to libgem_cuda), and the
# tests probe_in_gtest.cpp and gem_shaped_graph_probe.cu compiled into gem_cuda_tests for the run.
# Rounds 2 and 3 used an experiment-only switch in enqueueStep (GEM_EXPERIMENT_BODY) that is not on
# main; README.md says what it cut.
cd "$(dirname "$0")"
export LD_LIBRARY_PATH=$PWD/lib GEM_BINARY_DIR=$PWD GEM_SOURCE_DIR=$PWD GEM_TEST_CUDA_PLUGIN_DIR=$PWD/cuda_plugins
san=$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)
T=CudaBroadphase.EveryStrategyGivesTheGridsTrajectoriesBitForBit
export GEM_CUDA_DRIVER=device
mc="$san --tool memcheck --error-exitcode 9"
one() {  # NAME COMMAND...: RUNS runs, each in a fresh folder, its log in $OUT/mc-NAME-K.txt
  name=$1; shift
  for k in $(seq $RUNS); do
    w=$(mktemp -d)
    (cd $w && timeout 150 "$@" > $OUT/mc-$name-$k.txt 2>&1; echo "$name $k rc=$? $(grep -h 'ERROR SUMMARY' $OUT/mc-$name-$k.txt | head -1)")
  done
}
beside() {  # NAME OTHER-COMMAND...: the sanitized T three times while OTHER loops
  name=$1; shift
  rm -f /tmp/stop-bg
  ( while [ ! -f /tmp/stop-bg ]; do "$@" > /dev/null 2>&1; done ) &
  sleep 4
  RUNS=3 one $name $mc $PWD/gem_cuda_tests --gtest_filter=$T
  touch /tmp/stop-bg; wait
}
start_loop() { rm -f /tmp/stop-bg; ( while [ ! -f /tmp/stop-bg ]; do ./gem_cuda_tests --gtest_filter=$T > /dev/null 2>&1; done ) & sleep 4; }
stop_loop() { touch /tmp/stop-bg; wait; }
case "$1" in
1) start_loop
   RUNS=2 one control $mc $PWD/gem_cuda_tests --gtest_filter=$T
   for mode in trig module2 trigmodule2; do RUNS=3 one probe-$mode $mc $PWD/probe/probe2 8 $mode; done
   RUNS=3 one upload env GEM_CUDA_GRAPH_UPLOAD=1 $mc $PWD/gem_cuda_tests --gtest_filter=$T  # an experiment-only switch
   RUNS=3 one exclude-prepare $mc --kernel-name-exclude kns=prepare $PWD/gem_cuda_tests --gtest_filter=$T
   stop_loop ;;
2) start_loop
   for mode in none prepare empty empty1 tiny; do RUNS=2 one body-$mode env GEM_EXPERIMENT_BODY=$mode $mc $PWD/gem_cuda_tests --gtest_filter=$T; done
   RUNS=2 one padding0 $san --tool memcheck --padding 0 --error-exitcode 9 $PWD/gem_cuda_tests --gtest_filter=$T
   stop_loop ;;
3) beside other-graph0 env GEM_CUDA_GRAPH=0 ./gem_cuda_tests --gtest_filter=$T
   beside other-probe ./probe/probe2 64
   beside other-resident env GEM_CUDA_DRIVER=resident ./gem_cuda_tests --gtest_filter='CudaBackend.Resident*:CudaBackend.*Together*'
   RUNS=3 one alone-body-none env GEM_EXPERIMENT_BODY=none $mc $PWD/gem_cuda_tests --gtest_filter=$T ;;
4) start_loop
   RUNS=3 one probe-in-gtest env GEM_MEMCHECK_PROBE=plain $mc $PWD/gem_cuda_tests --gtest_filter=MemcheckProbe.*
   RUNS=3 one probe-edge32 $mc $PWD/probe/probe3 8 edge32
   RUNS=3 one probe-gemlinked-eager env CUDA_MODULE_LOADING=EAGER $mc $PWD/probe/probe3-gemlinked 8 plain
   RUNS=2 one probe-then-T env GEM_MEMCHECK_PROBE=plain $mc $PWD/gem_cuda_tests --gtest_filter=MemcheckProbe.*:$T
   stop_loop ;;
5) start_loop
   RUNS=3 one gemgraph env GEM_MEMCHECK_GEMGRAPH=gem $mc $PWD/gem_cuda_tests --gtest_filter=MemcheckProbe.GemShaped*
   RUNS=3 one gemgraph-noring env GEM_MEMCHECK_GEMGRAPH=noring $mc $PWD/gem_cuda_tests --gtest_filter=MemcheckProbe.GemShaped*
   stop_loop ;;
6) start_loop
   RUNS=4 one probe-shared-cudart $mc $PWD/probe/probe3-shared 8 plain
   RUNS=3 one probe-static-cudart $mc $PWD/probe/probe3 8 plain
   stop_loop ;;
7) start_loop
   for mode in upload memset realloc big kernels cub upload-memset-realloc-big-kernels-cub; do
     RUNS=2 one gg-$mode env GEM_MEMCHECK_GEMGRAPH=$mode $mc $PWD/gem_cuda_tests --gtest_filter=MemcheckProbe.GemShaped*
   done
   stop_loop ;;
*) echo "usage: $0 ROUND (1 to 7)" >&2; exit 2 ;;
esac
