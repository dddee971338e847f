#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-04 evening: where the Xeon of the H200 machine spends the 824-floe step,
# against the development machine's AMD core. Run from the repository root with .gpu-stage-cpu
# carried: before/ (4e89f89), head/ and any other build folders given as arguments (gem and
# libgem_core.so of each, made on the development machine), lib/ (their libraries), perf/ (perf and
# its libraries). Writes machine.txt, perf-stat-*.txt, perf-*.txt and rounds.txt under $OUT.
# Each binary runs through the development machine's own loader and libraries (lib/), whatever the
# machine's glibc is.
R=$PWD; S=$R/.gpu-stage-cpu; OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
{ date -u; nproc; lscpu; uptime; } > "$OUT/machine.txt" 2>&1
bench() {  # build [steps]
  echo "cd /tmp && GEM_SCENARIOS=$R/scenarios GEM_CPU_TIMING=1 taskset -c ${CORE:-3} $S/lib/ld-linux-x86-64.so.2 --library-path $S/$1:$S/lib $S/$1/gem bench --backend cpu --cases 824 --steps ${2:-4000} --threads 1"
}
run() {
  echo "$1: $(bash -c "$(bench "$1")" 2>&1 | grep -E '^824 |timing' | sed 's/  */ /g' | tr '\n' ' ')" | tee -a "$OUT/rounds.txt"
}
[ -d $S/perf ] || { mkdir -p /tmp/pf && tar xJf $S/perf.tar.xz -C /tmp/pf; }; PF=$S/perf; [ -d $PF ] || PF=/tmp/pf/perf
P="$S/lib/ld-linux-x86-64.so.2 --library-path $PF:$S/lib $PF/perf"
if [ "${ROUNDS_ONLY:-0}" != 1 ]; then
for b in before head; do
  $P stat -e cycles,instructions,branches,branch-misses,cache-misses -o "$OUT/perf-stat-$b.txt" -- bash -c "$(bench $b)" > /dev/null 2>&1
  $P record -F 4000 -o /tmp/perf-$b.data -- bash -c "$(bench $b 8000)" > /dev/null 2>&1
  $P report -i /tmp/perf-$b.data --no-children --sort dso,symbol --stdio 2>/dev/null | grep -v '^#' | grep -v '^$' | head -60 | cut -c1-200 > "$OUT/perf-$b.txt"
done
$P annotate -i /tmp/perf-head.data --stdio -l 2>/dev/null | head -3000 > "$OUT/perf-annotate-head.txt"
fi
builds=(before head "$@")
for r in $(seq ${ROUNDS:-6}); do
  echo "round $r" >> "$OUT/rounds.txt"
  if [ $((r % 2)) = 1 ]; then for b in "${builds[@]}"; do run "$b"; done
  else for ((i=${#builds[@]}-1; i>=0; i--)); do run "${builds[$i]}"; done; fi
done
uptime >> "$OUT/machine.txt"
# (The second run of the day, `ROUNDS_ONLY=1`, skipped the perf part: see README.md.)
