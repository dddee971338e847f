#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-07 (session 28): how disturbed the lent Xeon is while the 824-floe
# rounds run. Each bench runs pinned to CORE under bash's `time` (real against user + sys), and
# the machine's steal ticks (/proc/stat, the time the hypervisor ran something else on our vCPUs)
# are read before and after each round. Builds as in round.sh; writes under $OUT.
R=$PWD; S=$R/.gpu-stage-cpu; OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
L="$S/lib/ld-linux-x86-64.so.2"
BUILDS=${BUILDS:-"s39 s41"}
steal() { awk '/^cpu /{print $9}' /proc/stat; }
cpusteal() { awk -v c="cpu${CORE:-3}" '$1==c{print $9}' /proc/stat; }
TIMEFORMAT="real %R user %U sys %S"
export GEM_SCENARIOS=$R/scenarios
cd /tmp
for r in $(seq ${ROUNDS:-8}); do
  order="old $BUILDS"; [ $((r % 2)) = 0 ] && order=$(echo $order | tr ' ' '\n' | tac | tr '\n' ' ')
  echo "round $r steal-all $(steal) steal-core $(cpusteal)" >> "$OUT/steal.txt"
  for b in $order; do
    { time taskset -c ${CORE:-3} $L --library-path $S/$b:$S/lib $S/$b/gem bench --backend cpu --cases 824 --threads 1 --steps 4000 > /tmp/b.txt 2>&1; } 2> /tmp/t.txt
    echo "$b threads 1: $(grep '^824 ' /tmp/b.txt | sed 's/  */ /g' | awk '{for (i = 1; i <= NF; ++i) if ($i == "variable_radius") print $(i + 2)}') ms $(cat /tmp/t.txt)" >> "$OUT/steal.txt"
  done
done
echo "end steal-all $(steal) steal-core $(cpusteal)" >> "$OUT/steal.txt"
