#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-07 (session 30), third call: `gem bench --table cpu` of s47 (ce5f16a,
# the table with its independent-fields rows) on the lent Xeon, 824 floes over 20,000 steps and
# 10^5 floes over the bench's 595 timed steps (LONG=1: also over 5,995); then the 824-floe rounds
# of old against s45 on cores 3 and 9 (../xeon-2026-12-07b-profile/steal.sh). Writes under $OUT.
R=$PWD; S=$R/.gpu-stage-cpu; L=$S/lib/ld-linux-x86-64.so.2; OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
{ date -u; uptime; lscpu | grep 'Model name'; } > "$OUT/machine.txt"
gem() { (cd /tmp && GEM_SCENARIOS=$R/scenarios $L --library-path $S/s47:$S/lib $S/s47/gem "$@"); }
gem bench --table cpu --cases 824 --steps 20000 > "$OUT/table-824.txt" 2>&1
gem bench --table cpu --cases 100000 --steps 60000 > "$OUT/table-1e5.txt" 2>&1
[ "${LONG:-0}" = 1 ] && gem bench --table cpu --cases 100000 --steps 600000 > "$OUT/table-1e5-long.txt" 2>&1
for c in 3 9; do BUILDS="s45" ROUNDS=${ROUNDS:-10} CORE=$c OUT=$OUT/core$c bash "$R/bench/results/xeon-2026-12-07b-profile/steal.sh"; done
{ date -u; uptime; } >> "$OUT/machine.txt"
