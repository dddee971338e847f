#!/usr/bin/env bash
# Round 4: the CUDA suite of a staged build of 6b148d1 (scripts/stage-gpu.sh), then that build's
# CPU backend against ea816c2's (the session's start), 10^5 floes on 16 threads and on one (pinned)
# and 824 floes on one pinned core, alternated. Run from the repository root with .gpu-stage
# (the staged build) and .gpu-stage-cpu/before (ea816c2's gem and libgem_core.so) carried.
R=$PWD
OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
cd "$R/.gpu-stage"
export GEM_BINARY_DIR=$PWD GEM_SOURCE_DIR=$PWD GEM_TEST_CUDA_PLUGIN_DIR=$PWD/cuda_plugins
{ date -u; nproc; lscpu | grep "Model name"; uptime; nvidia-smi --query-gpu=name,driver_version --format=csv; } > "$OUT/machine4.txt" 2>&1
LD_LIBRARY_PATH=$PWD/lib timeout 400 ./gem_cuda_tests --gtest_color=no > "$OUT/cuda-tests.txt" 2>&1
echo "cuda tests exit $?" >> "$OUT/machine4.txt"
run() {  # build threads cases steps
  local b=$1 t=$2 c=$3 n=$4 pre="" lib=$R/.gpu-stage/lib gem=$R/.gpu-stage/gem
  [ "$t" = 1 ] && pre="taskset -c 3"
  [ "$b" = before ] && lib=$R/.gpu-stage-cpu/before:$R/.gpu-stage/lib gem=$R/.gpu-stage-cpu/before/gem
  (cd /tmp && LD_LIBRARY_PATH=$lib GEM_SCENARIOS=$R/.gpu-stage/scenarios GEM_CPU_TIMING=1 timeout 120 $pre $gem bench --backend cpu \
    --cases $c --steps $n --threads $t 2>&1) > /tmp/run.txt
  echo "$b threads $t cases $c: $(grep -E '^(10\^5|824) ' /tmp/run.txt | sed 's/  */ /g' | cut -d' ' -f8) ms; $(grep 'gem cpu timing' /tmp/run.txt)" | tee -a "$OUT/rounds4.txt"
}
for r in 1 2 3 4 5; do
  echo "round $r" >> "$OUT/rounds4.txt"
  run after 16 100000 20000; run before 16 100000 20000; run after 1 100000 20000; run before 1 100000 20000
done
for r in 1 2 3 4 5; do
  echo "824 round $r" >> "$OUT/rounds4.txt"
  run after 1 824 4000; run before 1 824 4000
done
uptime >> "$OUT/machine4.txt"
