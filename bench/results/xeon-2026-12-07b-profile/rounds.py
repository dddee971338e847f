#!/usr/bin/env python3
"""Issue "CPU speed", 2026-12-07 (session 28): the 824-floe rounds of a rounds-824.txt (round.sh)
or a steal.txt (steal.sh): each round's times and ratios to old (4e89f89), then per build the median
of the rounds' ratios, the ratio of the medians of the times, and the rounds over 1.75x.

  python3 rounds.py FILE"""
import re, statistics as st, sys
rounds=[];cur={}
for line in open(sys.argv[1]):
    if line.startswith('round'):
        if cur: rounds.append(cur)
        cur={}
    m=re.match(r'(\w+) threads 1: ([\d.]+) ms',line)
    if m: cur[m.group(1)]=float(m.group(2))
if cur: rounds.append(cur)
builds=[b for b in rounds[0] if b!='old']
for r in rounds: print(' '.join('%s %.4f'%(b,r[b]) for b in sorted(r)), ' '.join('old/%s %.3f'%(b, r['old']/r[b]) for b in builds))
for b in builds:
    ratios=[r['old']/r[b] for r in rounds]
    print(b,'median of ratios %.3f'%st.median(ratios),'ratio of medians %.3f'%(st.median([r['old'] for r in rounds])/st.median([r[b] for r in rounds])), 'median time %.4f'%st.median([r[b] for r in rounds]), 'rounds over 1.75: %d of %d'%(sum(x>1.75 for x in ratios), len(ratios)))
if len(builds)==2:
    a,b=builds; print('%s/%s median %.3f'%(a,b,st.median([r[a]/r[b] for r in rounds])))
print('old median', st.median([r['old'] for r in rounds]))
