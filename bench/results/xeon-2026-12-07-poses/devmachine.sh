#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-07, on the development machine (2 vCPUs): 10^5 floes on one pinned
# thread and on two, and the 824-floe field on one pinned core, each round alternating the builds.
# Builds (Release, CPU only) in directories named on the command line; old is 4e89f89's.
#   OLD=/tmp/bold ROUNDS=8 bash devmachine.sh /tmp/b24f /tmp/s25/b23ea3e /tmp/s25/b549490a
R=${ROUNDS:-8}
row() {  # row BUILD THREADS CASES STEPS: "round r BUILD threads t: X ms"
  local b=$1 t=$2 c=$3 n=$4 pin=""
  [ "$t" = 1 ] && pin="taskset -c 1"
  (cd /tmp && LD_LIBRARY_PATH=$b GEM_SCENARIOS=${SCENARIOS:-/work/main/scenarios} $pin $b/gem bench --backend cpu --cases "$c" --steps "$n" --threads "$t" 2>&1) |
    grep -E '^(10\^5|824) ' | awk '{for (i = 1; i <= NF; ++i) if ($i ~ /^[0-9]+\.[0-9]+$/) {print $i; exit}}'
}
for r in $(seq $R); do
  for b in "$@"; do for t in 1 2; do echo "1e5 round $r $(basename $b) threads $t: $(row $b $t 100000 60000) ms"; done; done
done
for r in $(seq $R); do
  for b in ${OLD:-/tmp/bold} "$@"; do echo "824 round $r $(basename $b) threads 1: $(row $b 1 824 4000) ms"; done
done
