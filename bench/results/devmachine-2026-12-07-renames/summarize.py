#!/usr/bin/env python3
"""summarize.py DIR: per build, the medians over the rounds of run.sh's figures.

threads.txt: 10^5 floes, ms a step on one thread and on two, and the median of the rounds' ratios.
rounds-824.txt: the 824-floe field, old / build by round and its median, and the medians of the times.
phases.txt: the median of each build's "steps by kind" figures, one thread and two."""
import collections, re, statistics, sys

d = sys.argv[1]
times = collections.defaultdict(lambda: collections.defaultdict(dict))
for line in open(f"{d}/threads.txt"):
    m = re.match(r"round (\d+) (\S+) threads (\d+): ([0-9.]+) ms", line)
    if m:
        times[m[2]][int(m[1])][int(m[3])] = float(m[4])
print("10^5 floes, ms a step (medians over the rounds); one thread / two by round, median")
for b, rounds in times.items():
    t1 = [v[1] for v in rounds.values() if 1 in v]
    t2 = [v[2] for v in rounds.values() if 2 in v]
    ratios = [v[1] / v[2] for v in rounds.values() if 1 in v and 2 in v]
    print(f"  {b}: 1 thread {statistics.median(t1):.4f}, 2 threads {statistics.median(t2):.4f};"
          f" ratios {' '.join(f'{x:.2f}' for x in ratios)}, median {statistics.median(ratios):.3f}")
r824 = collections.defaultdict(dict)
for line in open(f"{d}/rounds-824.txt"):
    m = re.match(r"round (\d+) (\S+) 824: ([0-9.]+) ms", line)
    if m:
        r824[int(m[1])][m[2]] = float(m[3])
builds = [b for b in next(iter(r824.values())) if b != "old"]
print("824 floes, one pinned core: old / build by round, median; medians of the times")
old = statistics.median(v["old"] for v in r824.values())
for b in builds:
    ratios = [v["old"] / v[b] for v in r824.values() if b in v and "old" in v]
    med = statistics.median(v[b] for v in r824.values() if b in v)
    print(f"  {b}: {' '.join(f'{x:.2f}' for x in ratios)}, median {statistics.median(ratios):.3f};"
          f" old {old:.4f} / {med:.4f} = {old / med:.3f}")
kinds = collections.defaultdict(list)
cur = None
for line in open(f"{d}/phases.txt"):
    m = re.match(r"round \d+ (\S+) threads (\d+)", line)
    if m:
        cur = (m[1], int(m[2]))
        continue
    m = re.search(r"steps by kind: (\d+) plain at ([0-9.]+) ms.*?(\d+) breaking or re-sorting at ([0-9.]+) ms, ([0-9.]+) ms a step.*?(\d+) right after those at ([0-9.]+) ms, ([0-9.]+) ms a step", line)
    if m and cur:
        kinds[cur].append((float(m[2]), float(m[4]), float(m[7]), float(m[5]) + float(m[8])))
print("10^5 floes, steps by kind (medians): plain ms, breaking or re-sorting ms, right after ms, the last two kinds' share of the mean step ms")
for (b, t), rows in sorted(kinds.items()):
    cols = [statistics.median(r[i] for r in rows) for i in range(4)]
    print(f"  {b}, {t} thread{'s' if t > 1 else ''}: plain {cols[0]:.4f}, breaking or re-sorting {cols[1]:.3f}, right after {cols[2]:.3f}, their share {cols[3]:.4f}")
