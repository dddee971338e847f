#!/usr/bin/env bash
# The README's load-study timing on the GPU machine (issue 5: the 70-run study under 10 s, batched),
# from a staged build: `bash .gpu-stage/load_study.sh [OUT]`. Runs the sweep with its cases together
# in one device state (GEM_CUDA_TIMING=1 prints where the host's time went), then one case per
# device state (--batch 1, 16 jobs), and compares the two summary.csv files but for wall_time_s.
set -uo pipefail
cd "$(dirname "$0")"
export LD_LIBRARY_PATH="$PWD/lib"
out="${1:-${OUT:-./gpu-out}}"
mkdir -p "$out"
nvidia-smi --query-gpu=name --format=csv,noheader
rm -rf /tmp/gem_load_batched /tmp/gem_load_single
/usr/bin/time -f "batched: %e s wall" env GEM_CUDA_TIMING=1 ./gem sweep scenarios/thesis/load_study.toml --out /tmp/gem_load_batched \
  > "$out/load_batched.log" 2>&1
head -1 "$out/load_batched.log"; grep "gem cuda timing\|wall" "$out/load_batched.log"
/usr/bin/time -f "one case per device state: %e s wall" ./gem sweep scenarios/thesis/load_study.toml --batch 1 --jobs 16 \
  --out /tmp/gem_load_single > "$out/load_single.log" 2>&1
tail -1 "$out/load_single.log"
cp /tmp/gem_load_batched/summary.csv "$out/load_batched_summary.csv"
cp /tmp/gem_load_single/summary.csv "$out/load_single_summary.csv"
python3 - "$out/load_batched_summary.csv" "$out/load_single_summary.csv" <<'PY'
import csv, sys
a, b = (list(csv.DictReader(open(f))) for f in sys.argv[1:3])
differ = [(x["name"], k) for x, y in zip(a, b) for k in x if k != "wall_time_s" and x[k] != y[k]]
print(f"{len(a)} and {len(b)} cases; cells that differ (wall_time_s aside): {len(differ)}", differ[:5])
PY
