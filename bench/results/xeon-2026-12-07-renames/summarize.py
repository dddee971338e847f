#!/usr/bin/env python3
"""Issue "CPU speed": the tables of docs/performance.md 3.20 from a record of
../xeon-2026-12-07-poses/run.sh, serial.sh or final.sh. Usage: summarize.py RECORD_DIR (holding
run-1/ and run-2/)."""
import re
import statistics as st
import sys

record = sys.argv[1]
row = re.compile(r'^(\w+) threads (\d+): ([\d.]+) ms')
kinds = re.compile(r'steps by kind: (\d+) plain at ([\d.]+) ms.*?(\d+) breaking or re-sorting at ([\d.]+) ms'
                   r'.*?(\d+) right after those at ([\d.]+) ms')

for run in ('run-1', 'run-2'):
    print(f'{run}: 10^5 floes, ms a step (plain / breaking or re-sorting / right after)')
    times = {}
    lines = []
    for line in open(f'{record}/{run}/scaling.txt'):
        m = row.match(line)
        if m:
            times[(m.group(1), int(m.group(2)))] = float(m.group(3))
            lines.append(f'  {m.group(1)} {int(m.group(2)):2} threads: {float(m.group(3)):.4f}')
            continue
        k = kinds.search(line)
        if k and lines:
            lines[-1] += f'  ({float(k.group(2)):.4f} / {float(k.group(4)):.2f} / {float(k.group(6)):.2f})'
    print('\n'.join(lines))
    for b in sorted({b for b, _ in times}):
        one = times.get((b, 1))
        if one:
            print(f'  {b}: ' + ', '.join(f'{t} threads {one / times[(b, t)]:.2f}x'
                                         for t in (2, 4, 8, 16) if (b, t) in times))

rounds = open(f'{record}/run-1/rounds-824.txt').read().split('round ')[1:]
if rounds:
    per_build, ratios = {}, {}
    for r in rounds:
        d = {m.group(1): float(m.group(3)) for m in map(row.match, r.splitlines()) if m}
        for b, t in d.items():
            per_build.setdefault(b, []).append(t)
            if b != 'old':
                ratios.setdefault(b, []).append(d['old'] / t)
    print(f'824 floes, one pinned core, {len(rounds)} alternated rounds')
    for b, t in per_build.items():
        print(f'  {b}: median {st.median(t):.4f} ms ({min(t):.4f} to {max(t):.4f})')
    for b, r in ratios.items():
        print(f'  old against {b}: median of the rounds\' ratios {st.median(r):.3f}x ({min(r):.2f}x to {max(r):.2f}x);'
              f' by the medians of the times {st.median(per_build["old"]) / st.median(per_build[b]):.3f}x')
