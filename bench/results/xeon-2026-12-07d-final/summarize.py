#!/usr/bin/env python3
"""The record's tables: python3 summarize.py FOLDER [COPIES] (first/, ceiling/; amd-copies.txt). Prints the 824-floe rounds
(old against each build, round by round: the median of the rounds' ratios and the ratio of the
medians of the times), the 10^5-floe scaling (ms a step at 1 to 16 threads, and 2 and 16 against 1)
from scaling.txt and long.txt, and the independent copies from copies.txt."""
import collections, os, re, statistics, sys
folder = sys.argv[1]
def path(name):
    p = os.path.join(folder, name)
    return p if os.path.exists(p) else None

if path('steal.txt'):
    rounds = []
    for line in open(path('steal.txt')):
        if line.startswith('round'): rounds.append({})
        m = re.match(r'(\S+) threads 1: ([\d.]+) ms', line)
        if m and rounds: rounds[-1][m[1]] = float(m[2])
    builds = sorted({b for r in rounds for b in r if b != 'old'})
    print(f"824 floes, one pinned core, {len(rounds)} rounds (old = 4e89f89 against each build):")
    for b in builds:
        ratios = [r['old'] / r[b] for r in rounds if 'old' in r and b in r]
        olds = [r['old'] for r in rounds if 'old' in r]
        times = [r[b] for r in rounds if b in r]
        print(f"  {b}: rounds " + " ".join(f"{x:.2f}" for x in ratios) +
              f"; median of the rounds' ratios {statistics.median(ratios):.3f}x, ratio of the medians "
              f"{statistics.median(olds) / statistics.median(times):.3f}x ({b} {statistics.median(times):.4f} ms, old {statistics.median(olds):.4f})")

def scaling(name, title):
    if not path(name): return
    runs = collections.defaultdict(list)  # build -> list of {threads: ms}
    serial = collections.defaultdict(dict)
    last = None
    for line in open(path(name)):
        m = re.match(r'(\S+) threads (\d+): ([\d.]+) ms', line)
        if m:
            b, t, ms = m[1], int(m[2]), float(m[3])
            if not runs[b] or t in runs[b][-1]: runs[b].append({})
            runs[b][-1][t] = ms
            last = (b, len(runs[b]) - 1, t)
            continue
        m = re.search(r'([\d.]+) ms a step between rounds on the calling thread', line)
        if m and last: serial[(last[0], last[1])][last[2]] = float(m[1])
    print(f"{title} (ms a step; serial = the pool's time between rounds on the calling thread):")
    print("  build  run  " + "  ".join(f"{t:>6}" for t in (1, 2, 4, 8, 16)) + "   2/1    16/1   serial at 2, 16")
    for b, rs in sorted(runs.items()):
        for k, r in enumerate(rs):
            s = serial[(b, k)]
            print(f"  {b:5}  {k + 1:3}  " + "  ".join(f"{r.get(t, 0):6.4f}" for t in (1, 2, 4, 8, 16)) +
                  f"  {r[1] / r[2]:5.2f}x {r[1] / r[16]:5.2f}x  {s.get(2, 0):.4f}, {s.get(16, 0):.4f}")
scaling('scaling.txt', "10^5 floes, the bench's 595 timed steps")
scaling('long.txt', "10^5 floes, 5,995 timed steps")

copies = path('copies.txt') or (sys.argv[2] if len(sys.argv) > 2 else None)
if copies:
    print("Independent one-thread copies, each pinned to a core of its own (ms a step of each copy):")
    base = {}
    for line in open(copies):
        m = re.match(r'steps (\d+) copies (\d+): (.*)', line)
        if not m: continue
        steps, k, times = int(m[1]), int(m[2]), [float(x) for x in m[3].split()]
        if k == 1 and steps not in base: base[steps] = times[0]
        mean = statistics.mean(times)
        timed = {60000: 595, 600000: 5995}.get(steps, steps)  # the bench's timed steps for --steps
        print(f"  {timed:>5} timed steps, {k:2} copies: mean {mean:.4f} ms (slowest {max(times):.4f}); "
              f"work done {k * base[steps] / mean:5.2f}x one copy's")
