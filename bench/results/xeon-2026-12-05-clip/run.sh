#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-05 night: the 824-floe field on one core of the lent machine's Xeon,
# 4e89f89 (old), c100981's step (head: f10dfbb with 4 tasks a thread, the same code) and 5a9e389
# (new2: the clipping that skips the edges a box corner rules out), alternated in 10 rounds; then
# where new2's one-core step spends its time (perf). Run from the repository root with
# .gpu-stage-cpu carried (see ../h100-2026-12-05-cpu/xeon.sh); writes under $OUT.
R=$PWD; S=$R/.gpu-stage-cpu; OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
SCALING=0 PERF=0 ROUNDS_1E5=0 ROUNDS_824=${ROUNDS_824:-10} ORDER_824="old head new2" NEW=new2 \
  bash "$R/bench/results/h100-2026-12-05-cpu/xeon.sh"
L="$S/lib/ld-linux-x86-64.so.2"
mkdir -p /tmp/pf && tar xJf "$S/perf.tar.xz" -C /tmp/pf
P="$L --library-path /tmp/pf/perf:$S/lib /tmp/pf/perf/perf"
(cd /tmp && GEM_SCENARIOS=$R/scenarios $P record -F 5000 -o /tmp/perf824.data -- taskset -c 3 $L --library-path $S/new2:$S/lib \
  $S/new2/gem bench --backend cpu --cases 824 --steps 40000 > /dev/null 2>&1)
$P report -i /tmp/perf824.data --no-children --sort sym --stdio 2>/dev/null | grep -v '^#' | grep -v '^$' | head -40 | cut -c1-200 > "$OUT/perf-824.txt"
