#!/usr/bin/env bash
# The development machine's run (AMD EPYC, 2 vCPUs): the 824-floe field on one core (core 1),
# old (4e89f89) against final2 (1c60427) and s24, ROUNDS (8) alternated rounds; then 10^5 floes
# on s24, 1 against 2 threads, 5 alternated rounds at the bench's 599 steps (--steps 60000, as
# in ../xeon-2026-12-06f-pool) and at 2,995 steps (--steps 300000), unless ONLY_824 is set.
# BUILDS_DIR holds one folder per build with its gem and libgem_core.so (CPU-only Release
# builds); devmachine-5e0cd0f.txt ran with s24 = 5e0cd0f, devmachine-1e7003d.txt with 1e7003d,
# devmachine-b181cfd.txt with b181cfd.
B=${BUILDS_DIR:-/tmp}; R=$PWD
ms() {  # ms BUILD THREADS CASES STEPS: the bench's ms a step
  local pin=""; [ "$2" = 1 ] && pin="taskset -c 1"
  (cd /tmp && LD_LIBRARY_PATH=$B/$1 GEM_SCENARIOS=$R/scenarios $pin $B/$1/gem bench --backend cpu --cases $3 --steps $4 --threads $2 2>&1) |
    grep -E '^(10\^5|824) ' | sed 's/  */ /g' | awk '{for (i = 1; i <= NF; ++i) if ($i == "variable_radius") print $(i + 2)}'
}
date -u; uptime
for r in $(seq ${ROUNDS:-8}); do
  order="old final2 s24"; [ $((r % 2)) = 0 ] && order="s24 final2 old"
  for b in $order; do echo "824 round $r $b threads 1: $(ms $b 1 824 4000) ms"; done
done
[ -n "$ONLY_824" ] || for steps in 60000 300000; do
  for r in $(seq 5); do
    order="1 2"; [ $((r % 2)) = 0 ] && order="2 1"
    for t in $order; do echo "10^5 --steps $steps round $r s24 threads $t: $(ms s24 $t 100000 $steps) ms"; done
  done
done
date -u; uptime
