import sys, re, statistics, collections
# summarize.py FILE: 10^5 one/two-thread ratios by build, and 824 old/build by round
t=collections.defaultdict(lambda: collections.defaultdict(dict)); e=collections.defaultdict(dict)
for line in open(sys.argv[1]):
    m=re.match(r'1e5 round (\d+) (\S+) threads (\d+): ([0-9.]+) ms', line.strip())
    if m: t[m.group(2)][int(m.group(1))][int(m.group(3))]=float(m.group(4))
    m=re.match(r'824 round (\d+) (\S+) threads 1: ([0-9.]+) ms', line.strip())
    if m: e[int(m.group(1))][m.group(2)]=float(m.group(3))
print('10^5 floes, one pinned thread against two:')
for b, rounds in t.items():
    r=[v[1]/v[2] for v in rounds.values() if 1 in v and 2 in v]
    t1=[v[1] for v in rounds.values()]; t2=[v[2] for v in rounds.values()]
    print('  %-10s 1 thread %s ms (median %.4f); 2 threads %s ms (median %.4f); ratios %s, median %.3f' % (b, ' '.join('%.3f'%x for x in t1), statistics.median(t1), ' '.join('%.3f'%x for x in t2), statistics.median(t2), ' '.join('%.2f'%x for x in r), statistics.median(r)))
builds=[b for b in next(iter(e.values())).keys() if b!='bold']
print('824 floes, one pinned core, old (bold = 4e89f89) / build by round:')
for b in builds:
    r=[v['bold']/v[b] for v in e.values() if b in v and 'bold' in v]
    print('  %-10s %s; median %.3f; medians of times old %.4f build %.4f' % (b, ' '.join('%.2f'%x for x in sorted(r)), statistics.median(r), statistics.median(v['bold'] for v in e.values()), statistics.median(v[b] for v in e.values())))
