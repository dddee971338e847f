#!/usr/bin/env python3
"""Issue "CPU speed", 2026-12-07 (session 28): each function's share of the samples of
profile.sh's perf script output, for two runs side by side (the lent Xeon's and the development
machine's AMD core, say). perf's own report left the Xeon's libm unnamed; this names the library's
functions from its symbol table (nm) and the library's load address found from the samples.

  python3 shares.py LIB SAMPLES_A.txt.gz SAMPLES_B.txt.gz

LIB is the libgem_core.so both runs used (the s39 build: main at 75a2694)."""
import collections, gzip, re, subprocess, sys

lib, runs = sys.argv[1], sys.argv[2:]
syms = []
for line in subprocess.run(['nm', '-S', '-C', lib], capture_output=True, text=True).stdout.splitlines():
    m = re.match(r'^([0-9a-f]+) ([0-9a-f]+) ([tTwW]) (.*)$', line)
    if m:
        syms.append((int(m.group(1), 16), int(m.group(2), 16), m.group(4)))
byName = {name.split('(')[0]: (a, n) for a, n, name in syms}


def offsets(path):
    """The library's samples as offsets into it, and every sample's count."""
    rows, total, libm = [], 0, 0
    for line in gzip.open(path, 'rt'):
        total += 1
        libm += 'libm.so' in line
        m = re.match(r'\S+\s+([0-9a-f]+) (.*) \((.*)\)$', line.strip())
        if m and 'libgem_core' in m.group(3):
            rows.append((int(m.group(1), 16), m.group(2)))
    # Each named sample puts the (page-aligned) load address at or just below ip - its function's
    # start; a name that matches another function's misleads, so the most common answer is taken.
    votes = collections.Counter((ip - byName[s][0]) - (ip - byName[s][0]) % 4096 for ip, s in rows if s in byName)
    base = votes.most_common(1)[0][0]
    return collections.Counter(ip - base for ip, _ in rows), total, libm


counts = [offsets(r) for r in runs]
table = []
for a, n, name in syms:
    shares = [100 * sum(v for k, v in c.items() if a <= k < a + n) / t for c, t, _ in counts]
    if max(shares) > float(__import__("os").environ.get("SHARE_MIN", "0.8")):
        table.append((shares, name[:100]))
table.sort(reverse=True)
print(' '.join('%7s' % ('run%d' % i) for i in range(len(runs))), ' function (% of all samples)')
for shares, name in table:
    print(' '.join('%7.2f' % s for s in shares), '', name)
print(' '.join('%7.2f' % (100 * m / t) for _, t, m in counts), '', 'libm (sincos, the world vertices\' turn)')
