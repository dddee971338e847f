#!/usr/bin/env bash
# Where the 10^5-floe step of 8aa28e4 (the chunked filter and the pose pass through locals) spends
# its time on the lent machine's Xeon: perf on 16 threads (perf-16.txt, perf-16-threads.txt, by
# ../h100-2026-12-05-cpu/xeon.sh) and on one pinned thread (perf-1.txt), and the thread scaling
# (scaling.txt). Run from the repository root with .gpu-stage-cpu carried (new/ = 8aa28e4, and
# perf.tar.xz: perf and its libraries from the development machine); writes under $OUT.
R=$PWD; S=$R/.gpu-stage-cpu; OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
SCALING=1 SCALING_BUILDS=new PERF=1 ROUNDS_824=0 ROUNDS_1E5=0 BUILDS=new NEW=new TABLE=0 bash "$R/bench/results/h100-2026-12-05-cpu/xeon.sh"
L="$S/lib/ld-linux-x86-64.so.2"; P="$L --library-path /tmp/pf/perf:$S/lib /tmp/pf/perf/perf"
(cd /tmp && GEM_SCENARIOS=$R/scenarios $P record -F 2000 -o /tmp/perf1.data -- taskset -c 3 $L --library-path $S/new:$S/lib $S/new/gem bench --backend cpu --cases 100000 --steps 300000 --threads 1 > /dev/null 2>&1)
$P report -i /tmp/perf1.data --no-children --sort sym --stdio 2>/dev/null | grep -v '^#' | grep -v '^$' | head -70 | cut -c1-220 > "$OUT/perf-1.txt"
