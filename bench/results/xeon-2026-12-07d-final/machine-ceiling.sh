#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-07 (session 30): how much of the 10^5-floe step's poor scaling on the
# lent Xeon is the machine's own. Writes under $OUT:
#   copies.txt     k = 1, 2, 4, 8, 16 independent copies of the one-thread bench (HEAD build), each
#                  pinned to a core of its own, over 5,995 and 595 timed steps: the ms a step of each
#                  copy. k copies at the one-copy time would be k times the work done; a thread pool
#                  on k cores can do no better than what k independent copies get.
#   pinning.txt    HEAD at two threads pinned to two cores (2,3 and 3,11) and unpinned, and one
#                  thread unpinned, over 5,995 steps, with the pool's account
#   perfstat.txt   perf stat (task clock, cycles, instructions) of HEAD at 1 (pinned), 2 and 16
#                  threads over 5,995 steps: whether the threads' extra time is more cycles at the
#                  same instructions (waiting on memory or on other cores) or a slower clock
#   steal.txt      the 824-floe rounds as in run.sh (ROUNDS)
R=$PWD; S=$R/.gpu-stage-cpu; L=$S/lib/ld-linux-x86-64.so.2; OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
HEAD=${HEAD:-s45}
{ date -u; uptime; } >> "$OUT/machine.txt"
export GEM_SCENARIOS=$R/scenarios
ms() { grep -E '^10\^5 ' "$1" | sed 's/  */ /g' | awk '{for (i = 1; i <= NF; ++i) if ($i == "variable_radius") print $(i + 2)}'; }
cd /tmp
for steps in 600000 60000; do for k in 1 2 4 8 16 1; do
  for ((i = 0; i < k; ++i)); do
    taskset -c $i $L --library-path $S/$HEAD:$S/lib $S/$HEAD/gem bench --backend cpu --cases 100000 --threads 1 --steps $steps > /tmp/copy-$i.txt 2>&1 &
  done; wait
  line="steps $steps copies $k:"; for ((i = 0; i < k; ++i)); do line="$line $(ms /tmp/copy-$i.txt)"; done
  echo "$line" >> "$OUT/copies.txt"
done; done
for pin in "taskset -c 2,3" "taskset -c 3,11" "" ; do for t in 2 1; do
  [ "$t" = 1 ] && [ -n "$pin" ] && continue
  GEM_CPU_TIMING=1 $pin $L --library-path $S/$HEAD:$S/lib $S/$HEAD/gem bench --backend cpu --cases 100000 --threads $t --steps 600000 > /tmp/p.txt 2>&1
  echo "threads $t pin '${pin}': $(ms /tmp/p.txt) ms" >> "$OUT/pinning.txt"; grep '^gem cpu' /tmp/p.txt | sed 's/^/  /' >> "$OUT/pinning.txt"
done; done
mkdir -p /tmp/pf && tar xJf "$S/perf.tar.xz" -C /tmp/pf
P="$L --library-path /tmp/pf/perf:$S/lib /tmp/pf/perf/perf"
for t in 1 2 16; do
  pin=""; [ "$t" = 1 ] && pin="taskset -c 3"
  echo "== threads $t" >> "$OUT/perfstat.txt"
  $P stat -e task-clock,cycles,instructions -o /tmp/ps.txt -- $pin $L --library-path $S/$HEAD:$S/lib $S/$HEAD/gem bench --backend cpu --cases 100000 --threads $t --steps 600000 > /tmp/p.txt 2>&1
  echo "$(ms /tmp/p.txt) ms a step" >> "$OUT/perfstat.txt"; grep -v '^#' /tmp/ps.txt | grep -v '^$' >> "$OUT/perfstat.txt"
done
cd "$R" && [ "${ROUNDS:-10}" -gt 0 ] && BUILDS="${BUILDS:-s41 s45}" ROUNDS=${ROUNDS:-10} CORE=${CORE:-5} OUT=$OUT bash "$R/bench/results/xeon-2026-12-07b-profile/steal.sh"
{ date -u; uptime; } >> "$OUT/machine.txt"
