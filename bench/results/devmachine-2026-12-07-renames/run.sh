#!/usr/bin/env bash
# Issue "CPU speed", 2026-12-07 (session 26), on the development machine (2 vCPUs): BUILDS (default
# "base rename final", directories under B holding a gem and its libgem_core.so) alternated round
# by round, ROUNDS (8) rounds. Each round: 10^5 floes on one thread pinned to core 1, then on two
# threads, build after build (the order reversed every other round), each with GEM_CPU_TIMING=1
# (the phase line, the steps by kind and the pool's account); then the 824-floe field on one
# pinned core, OLD (4e89f89) first and the builds after it, likewise reversed every other round.
# Writes threads.txt, phases.txt and rounds-824.txt under OUT; summarize.py reads them.
R=$(cd "$(dirname "$0")/../../.." && pwd); OUT=${OUT:-/tmp/out}; mkdir -p "$OUT"
B=${B:-/tmp/s26}; BUILDS=${BUILDS:-base rename final}; OLD=${OLD:-/tmp/bold}; ROUNDS=${ROUNDS:-8}
{ date -u; nproc; lscpu | head -20; uptime; } > "$OUT/machine.txt" 2>&1
gem() {  # gem DIR ARGS...
  local d=$1; shift
  (cd /tmp && LD_LIBRARY_PATH=$d GEM_SCENARIOS=$R/scenarios $PIN "$d/gem" "$@")
}
ms() { awk '{for (i = 1; i <= NF; ++i) if ($i == "variable_radius") {print $(i + 2); exit}}'; }
for r in $(seq "$ROUNDS"); do
  order=$BUILDS; [ $((r % 2)) = 0 ] && order=$(echo $order | tr ' ' '\n' | tac | tr '\n' ' ')
  for b in $order; do
    for t in 1 2; do
      PIN=""; [ $t = 1 ] && PIN="taskset -c 1"
      text=$(PIN="$PIN" GEM_CPU_TIMING=1 gem "$B/$b" bench --backend cpu --cases 100000 --steps 60000 --threads $t 2>&1)
      echo "round $r $b threads $t: $(echo "$text" | grep -E '^10\^5 ' | ms) ms" | tee -a "$OUT/threads.txt"
      { echo "round $r $b threads $t"; echo "$text" | grep '^gem cpu' | sed 's/^/  /'; } >> "$OUT/phases.txt"
    done
  done
  order="old $BUILDS"; [ $((r % 2)) = 0 ] && order=$(echo $order | tr ' ' '\n' | tac | tr '\n' ' ')
  for b in $order; do
    d="$B/$b"; [ "$b" = old ] && d=$OLD
    echo "round $r $b 824: $(PIN="taskset -c 1" gem "$d" bench --backend cpu --cases 824 --steps 4000 --threads 1 2>&1 | grep -E '^824 ' | ms) ms" | tee -a "$OUT/rounds-824.txt"
  done
done
uptime >> "$OUT/machine.txt"
