#!/usr/bin/env bash
# The README's record run, on the GPU machine (stage-gpu.sh copies this to .gpu-stage/record.sh):
#   bash .gpu-stage/record.sh OUT
# writes OUT/bench.txt and OUT/bench.tgz (gem bench --table all, its CSVs packed: the number of files
# that come back from the machine is limited), OUT/ncu-824.txt and OUT/ncu-1e6.txt (ncu's time per
# kernel over 15 steps, kernels launched one by one: GEM_CUDA_GRAPH=0), OUT/timing.txt (the host's
# part, GEM_CUDA_TIMING=1) and OUT/device.txt.
set -uo pipefail
stage="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
out="${1:?usage: record.sh OUT}"
cd "$stage"
export LD_LIBRARY_PATH="$stage/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
{ date -u; nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; } > "$out/device.txt"
mkdir -p "$out/bench"
./gem bench --table all --csv "$out/bench/" > "$out/bench.txt" 2>&1
tar czf "$out/bench.tgz" -C "$out" bench && rm -rf "$out/bench"
ncu="$(command -v ncu || ls /opt/nvidia/nsight-compute/*/ncu 2>/dev/null | head -1)"
if [ -n "$ncu" ]; then
  GEM_CUDA_GRAPH=0 "$ncu" --clock-control none --metrics gpu__time_duration.sum --launch-skip 6000 --launch-count 600 \
    --print-summary per-kernel ./gem bench --table step --backend cuda --cases 824 --steps 400 > "$out/ncu-824.txt" 2>&1
  GEM_CUDA_GRAPH=0 "$ncu" --clock-control none --metrics gpu__time_duration.sum --launch-skip 3000 --launch-count 600 \
    --print-summary per-kernel ./gem bench --table step --backend cuda --cases 1000000 --broadphase uniform_grid --steps 200 \
    > "$out/ncu-1e6.txt" 2>&1
fi
GEM_CUDA_TIMING=1 ./gem bench --table step --backend cuda --cases 824 100000 1000000 --broadphase uniform_grid variable_radius \
  --steps 400 > "$out/timing.txt" 2>&1
tail -n 3 "$out/bench.txt"
grep "gem cuda timing" "$out/timing.txt" | cut -c1-200
