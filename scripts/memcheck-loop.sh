#!/usr/bin/env bash
# Runs one command under compute-sanitizer memcheck RUNS times, AT_ONCE of them side by side on the
# GPU, and tallies the runs that report errors (docs/reliability.md, docs/performance.md 6).
#   scripts/memcheck-loop.sh RUNS AT_ONCE OUTDIR -- COMMAND [ARGS...]
# Run K works in OUTDIR/work-K (so give COMMAND as an absolute path); its log goes to
# OUTDIR/run-K.txt, the tally (also printed) to OUTDIR/tally.txt. Exit 0 when every run was clean,
# 1 otherwise.
#
# With AT_ONCE 1 each run waits (up to MEMCHECK_WAIT_S seconds, 300 by default) until no other
# process computes on the GPU, and the tally says how many runs still had company at some point
# (nvidia-smi is polled every second while a run lasts). That is the condition memcheck's promise
# for the graph path is made under: compute-sanitizer itself faults on the graph path's WHILE loop
# when another context shares the GPU (docs/performance.md 6), so a report from a shared run says
# nothing about GEM. AT_ONCE above 1 shares the GPU on purpose, to reproduce that fault.
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
rm -f "$out"/run-*.txt "$out"/company-*.txt "$out/exit-codes.txt"
start=$(date +%s)

# The PIDs computing on the GPU, one a line (none when nvidia-smi is missing).
gpu_pids() { nvidia-smi --query-compute-apps=pid --format=csv,noheader 2>/dev/null | tr -d ' '; }

if [ "$at_once" = 1 ]; then
  for k in $(seq "$runs"); do
    waited=0
    while [ -n "$(gpu_pids)" ] && [ $waited -lt "${MEMCHECK_WAIT_S:-300}" ]; do sleep 1; waited=$((waited + 1)); done
    mkdir -p "$out/work-$k"
    (cd "$out/work-$k" && exec "$sanitizer" --tool memcheck --error-exitcode 9 "$@") > "$out/run-$k.txt" 2>&1 &
    run=$!
    # Company: more processes on the GPU than this run's one, at any poll. (In a container
    # nvidia-smi may show the host's PIDs, or none: then the run's own is not seen either, and the
    # tally says company is unknown.)
    : > "$out/company-$k.txt"
    seen=0
    while kill -0 $run 2>/dev/null; do
      count=$(gpu_pids | wc -l)
      [ "$count" -ge 1 ] && seen=1
      [ "$count" -gt 1 ] && echo "$count processes on the GPU at $(date -u +%T)" >> "$out/company-$k.txt"
      sleep 1
    done
    [ $seen = 1 ] || echo "unknown: nvidia-smi never showed this run's own process" >> "$out/company-$k.txt"
    wait $run
    echo "$k $?" >> "$out/exit-codes.txt"
  done
else
  export sanitizer out
  seq "$runs" | xargs -P "$at_once" -I{} bash -c \
    'mkdir -p "$out/work-{}" && cd "$out/work-{}" && "$sanitizer" --tool memcheck --error-exitcode 9 "$@" > "$out/run-{}.txt" 2>&1; echo "{} $?" >> "$out/exit-codes.txt"' _ "$@"
fi
seconds=$(($(date +%s) - start))
bad=$(awk '$2 != 0' "$out/exit-codes.txt" | wc -l)
{
  echo "memcheck loop: $runs runs, $at_once at once, $seconds s: $((runs - bad)) clean, $bad with errors or a failed exit"
  echo "command: $*"
  if [ "$at_once" = 1 ]; then
    shared=$(grep -L unknown "$out"/company-*.txt | xargs -r grep -l processes | wc -l)
    unknown=$(grep -l unknown "$out"/company-*.txt | wc -l)
    echo "runs that shared the GPU with another process at some point: $shared of $runs ($unknown runs could not tell)"
  fi
  # The error counts the tool reported, run by run (a run that ended early may print none).
  grep -h "ERROR SUMMARY" "$out"/run-*.txt | sort | uniq -c
} | tee "$out/tally.txt"
[ "$bad" = 0 ]
