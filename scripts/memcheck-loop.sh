#!/usr/bin/env bash
# Runs one command under compute-sanitizer memcheck RUNS times, AT_ONCE of them side by side on the
# GPU, and tallies the runs that report errors (docs/reliability.md, docs/performance.md 6).
#   scripts/memcheck-loop.sh RUNS AT_ONCE OUTDIR -- COMMAND [ARGS...]
# Run K works in OUTDIR/work-K (so give COMMAND as an absolute path); its log goes to
# OUTDIR/run-K.txt, the tally (also printed) to OUTDIR/tally.txt. Exit 0 when every run was clean,
# 1 otherwise. AT_ONCE 1 gives each run the GPU to itself; more at once share it, which is when the
# graph path's unexplained report appears (docs/performance.md 6).
# scripts/memcheck/while_graph_probe.cu is a GEM-free control to run the same way (built with
# `nvcc -O2 -arch=sm_90 -o while_graph_probe scripts/memcheck/while_graph_probe.cu scripts/memcheck/second_module.cu`).
set -uo pipefail
if [ $# -lt 5 ] || [ "$4" != "--" ]; then
  echo "usage: $0 RUNS AT_ONCE OUTDIR -- COMMAND [ARGS...]" >&2
  exit 2
fi
runs=$1 at_once=$2 out=$3
shift 4
sanitizer="$(command -v compute-sanitizer || echo /usr/local/cuda/bin/compute-sanitizer)"
mkdir -p "$out"
rm -f "$out"/run-*.txt "$out/exit-codes.txt"
start=$(date +%s)
export sanitizer out
seq "$runs" | xargs -P "$at_once" -I{} bash -c \
  'mkdir -p "$out/work-{}" && cd "$out/work-{}" && "$sanitizer" --tool memcheck --error-exitcode 9 "$@" > "$out/run-{}.txt" 2>&1; echo "{} $?" >> "$out/exit-codes.txt"' _ "$@"
seconds=$(($(date +%s) - start))
bad=$(awk '$2 != 0' "$out/exit-codes.txt" | wc -l)
{
  echo "memcheck loop: $runs runs, $at_once at once, $seconds s: $((runs - bad)) clean, $bad with errors or a failed exit"
  echo "command: $*"
  # The error counts the tool reported, run by run (a run that ended early may print none).
  grep -h "ERROR SUMMARY" "$out"/run-*.txt | sort | uniq -c
} | tee "$out/tally.txt"
[ "$bad" = 0 ]
