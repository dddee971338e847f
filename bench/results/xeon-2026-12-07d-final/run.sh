#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-07 (session 30), on a lent machine's Xeon: the previous session's code
# (s45 = ae3e98f, main) against the main before it (s41 = 4a8c90e) and the issue's base (old =
# 4e89f89). Run from the repository root with .gpu-stage-cpu carried (old, s41, s45: gem and
# libgem_core.so of Release builds made on the development machine with -DGEM_DISABLE_CUDA=ON; lib:
# their libraries and the development machine's loader, so every build calls the same libm;
# perf.tar.xz: perf and its libraries). Writes under $OUT:
#   machine.txt    lscpu, uptime at the start and the end
#   steal.txt      the 824-floe field on one pinned core, old against s41 and s45, alternated rounds
#                  (../xeon-2026-12-07b-profile/steal.sh: real, user and sys, and the steal ticks)
#   scaling.txt    10^5 floes at 1 to 16 threads over the bench's 595 timed steps, with the pool's
#                  account (../xeon-2026-12-06f-pool/diagnose.sh), two rounds of each build
#   long.txt       the same over 5,995 timed steps (--steps 600000)
#   perf-16.txt    perf's symbols for s45 at 16 threads over the long run, all threads together
#   table-cpu.txt  s45's `gem bench --table cpu`
R=$PWD; S=$R/.gpu-stage-cpu; L=$S/lib/ld-linux-x86-64.so.2; OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
BUILDS=${BUILDS:-"s41 s45"}; HEAD=${HEAD:-s45}
{ date -u; nproc; lscpu | head -20; uptime; } > "$OUT/machine.txt" 2>&1
BUILDS="$BUILDS" ROUNDS=${ROUNDS:-10} CORE=${CORE:-3} OUT=$OUT bash "$R/bench/results/xeon-2026-12-07b-profile/steal.sh"
for round in 1 2; do
  BUILDS="$BUILDS" THREADS="1 2 4 8 16" ROUNDS_824=0 OUT=$OUT/scaling-$round bash "$R/bench/results/xeon-2026-12-06f-pool/diagnose.sh"
  { echo "== round $round"; cat "$OUT/scaling-$round/scaling.txt"; } >> "$OUT/scaling.txt"; rm -rf "$OUT/scaling-$round"
  BUILDS=$(echo $BUILDS | tr ' ' '\n' | tac | tr '\n' ' ')
done
for b in $BUILDS; do for t in 1 2 4 8 16; do
  pin=""; [ "$t" = 1 ] && pin="taskset -c ${CORE:-3}"
  text=$(cd /tmp && GEM_SCENARIOS=$R/scenarios GEM_CPU_TIMING=1 $pin $L --library-path $S/$b:$S/lib $S/$b/gem bench --backend cpu --cases 100000 --threads $t --steps 600000 2>&1)
  echo "$b threads $t: $(echo "$text" | grep -E '^10\^5 ' | sed 's/  */ /g' | awk '{for (i = 1; i <= NF; ++i) if ($i == "variable_radius") print $(i + 2)}') ms" >> "$OUT/long.txt"
  echo "$text" | grep '^gem cpu' | sed 's/^/  /' >> "$OUT/long.txt"
done; done
mkdir -p /tmp/pf && tar xJf "$S/perf.tar.xz" -C /tmp/pf
P="$L --library-path /tmp/pf/perf:$S/lib /tmp/pf/perf/perf"
(cd /tmp && GEM_SCENARIOS=$R/scenarios $P record -F 4000 -o /tmp/perf16.data -- $L --library-path $S/$HEAD:$S/lib $S/$HEAD/gem bench --backend cpu --cases 100000 --steps 600000 --threads 16 > /dev/null 2>&1)
$P report -i /tmp/perf16.data --no-children --sort sym --stdio 2>/dev/null | grep -v '^#' | grep -v '^$' | head -80 | cut -c1-200 > "$OUT/perf-16.txt"
(cd /tmp && GEM_SCENARIOS=$R/scenarios $L --library-path $S/$HEAD:$S/lib $S/$HEAD/gem bench --backend cpu --table cpu --steps 60000 > "$OUT/table-cpu.txt" 2>&1)
{ date -u; uptime; } >> "$OUT/machine.txt"
