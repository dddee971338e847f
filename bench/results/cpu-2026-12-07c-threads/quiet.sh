#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-07 (session 29), on a lent machine's Xeon. The 824-floe field on one
# pinned core (CORE, 3), old (4e89f89) against the builds in BUILDS, in ROUNDS alternated rounds
# under bash's `time` with the steal ticks (../xeon-2026-12-07b-profile/steal.sh); then 10^5 floes
# at THREADS with the pool's account, each build in turn (../xeon-2026-12-06f-pool/diagnose.sh:
# the bench's 595 timed steps), and the same field over 5,995 timed steps at LONG_THREADS. Run
# from the repository root with .gpu-stage-cpu carried (old, lib and the builds); writes under $OUT.
R=$PWD; S=$R/.gpu-stage-cpu; L=$S/lib/ld-linux-x86-64.so.2; OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
BUILDS=${BUILDS:-"s41 s42"}
{ date -u; nproc; lscpu | head -20; uptime; } > "$OUT/machine.txt" 2>&1
[ "${ROUNDS:-20}" -gt 0 ] && BUILDS="$BUILDS" ROUNDS=${ROUNDS:-20} CORE=${CORE:-3} OUT=$OUT bash "$R/bench/results/xeon-2026-12-07b-profile/steal.sh"
BUILDS="$BUILDS" THREADS="${THREADS:-1 2 4 8 16}" ROUNDS_824=0 OUT=$OUT/scaling bash "$R/bench/results/xeon-2026-12-06f-pool/diagnose.sh"
for b in $BUILDS; do for t in ${LONG_THREADS:-1 2 16}; do
  pin=""; [ "$t" = 1 ] && pin="taskset -c ${CORE:-3}"
  text=$(cd /tmp && GEM_SCENARIOS=$R/scenarios GEM_CPU_TIMING=1 $pin $L --library-path $S/$b:$S/lib $S/$b/gem bench --backend cpu --cases 100000 --threads $t --steps 600000 2>&1)
  echo "$b threads $t: $(echo "$text" | grep -E '^10\^5 ' | sed 's/  */ /g' | awk '{for (i = 1; i <= NF; ++i) if ($i == "variable_radius") print $(i + 2)}') ms" >> "$OUT/long.txt"
  echo "$text" | grep '^gem cpu' | sed 's/^/  /' >> "$OUT/long.txt"
done; done
{ date -u; uptime; } >> "$OUT/machine.txt"
