#!/usr/bin/env bash
# Where the host's time goes in the batched load study: perf (carried from the development machine).
S="$(cd "$(dirname "$0")" && pwd)"; out="${1:-$OUT}"; cd "$S"
P() { LD_LIBRARY_PATH="$S/perf/lib" "$S/perf/perf" "$@"; }
rm -rf /tmp/lb
P record -F 999 --call-graph dwarf -o /tmp/p.data -- env LD_LIBRARY_PATH="$S/lib" GEM_CUDA_TIMING=1 ./gem sweep scenarios/thesis/load_study.toml --out /tmp/lb > "$out/sweep.txt" 2>&1
echo "perf record exit $?"; tail -3 "$out/sweep.txt"
P report -i /tmp/p.data --stdio --no-children --sort comm,dso 2>/dev/null | grep -v "^$" | grep -v "^#" | head -30 > "$out/perf-dso.txt"; cat "$out/perf-dso.txt"
P report -i /tmp/p.data --stdio --no-children --sort symbol -g none 2>/dev/null | grep -v "^$" | grep -v "^#" | head -80 > "$out/perf-flat.txt"; head -40 "$out/perf-flat.txt"
P report -i /tmp/p.data --stdio --children --sort symbol -g none 2>/dev/null | grep -v "^$" | grep -v "^#" | head -120 > "$out/perf-inclusive.txt"; head -60 "$out/perf-inclusive.txt"
