#!/usr/bin/env python3
"""Two against one thread, round by round, from amd.sh's scaling.txt (or quiet.sh's long.txt):
for each build and step count, each round's one-thread and two-thread bench figures, their ratio,
the pool's serial time (ms a step between rounds on the calling thread) and the medians."""
import re, sys, statistics, collections
rows = collections.defaultdict(dict)  # (build, steps) -> round -> {threads: ms}
serial = collections.defaultdict(list)
last = None
for line in open(sys.argv[1]):
    m = re.match(r'round (\d+) steps (\d+) (\S+) threads (\d+): ([\d.]+) ms', line)
    if m:
        r, steps, b, t, ms = int(m[1]), int(m[2]), m[3], int(m[4]), float(m[5])
        rows[(b, steps)].setdefault(r, {})[t] = ms
        last = (b, steps, r, t)
        continue
    m = re.search(r'([\d.]+) ms a step between rounds on the calling thread', line)
    if m and last:
        serial[(last[0], last[1])].append(float(m[1]))
for (b, steps), rounds in sorted(rows.items()):
    ratios = [v[1] / v[2] for v in rounds.values() if 1 in v and 2 in v]
    ones = [v[1] for v in rounds.values() if 1 in v]
    twos = [v[2] for v in rounds.values() if 2 in v]
    timed = {60000: 595, 600000: 5995}.get(steps, steps)  # the bench times 5 chunks of requested x 1000 / 100,003 / 5 steps
    print(f"{b} {timed} timed steps: " +
          " ".join(f"{v.get(1, 0):.4f}/{v.get(2, 0):.4f}={v[1] / v[2]:.2f}x" for v in rounds.values() if 1 in v and 2 in v))
    print(f"  median of the rounds' ratios {statistics.median(ratios):.2f}x; ratio of the medians "
          f"{statistics.median(ones) / statistics.median(twos):.2f}x; best two-thread round {min(ones) / min(twos):.2f}x (fastest one against fastest two); "
          f"serial on two threads {statistics.median(serial[(b, steps)]):.4f} ms a step (median)")
