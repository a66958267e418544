import json, sys, re, statistics as st
from collections import defaultdict
base = sys.argv[1]
doc = json.load(open(base + '.json'))
sc = doc['scenarios'][0]; sf = sc['strongest_sensor_free']
lines = [l.split() for l in open(base + '.err') if l.startswith('BAND')]
# segment by seeds
recs = []; seed = 0; last = None
for p in lines:
    key = (int(p[1]), int(p[2]), int(p[3]))
    if last is not None and key < last: seed += 1
    last = key
    d = {'seed': seed, 'key': key, 'taus': p[6]}
    full = ' '.join(p); head, _, tail = full.partition(' WHATIF ')
    toks = head.split()[7:]
    if tail:
        import re as _re
        d['K0lin'] = float(_re.search(r'K0lin (\S+)', tail).group(1)); d['Slin'] = float(_re.search(r'Slin (\S+)', tail).group(1))
        for si, a, b_, c, n in _re.findall(r's(\d): i(\S+) l(\S+) b(\S+) n(\S+)', tail):
            nm = ['hb', 'hh', 'bed'][int(si)]
            d['w_i_' + nm], d['w_l_' + nm], d['w_b_' + nm], d['w_n_' + nm] = float(a), float(b_), float(c), float(n)
    i = 0; vals = {}
    while i < len(toks):
        t = toks[i]
        if t == '|': i += 1; continue
        if re.match(r'^b[0-9.-]', t):
            vals.setdefault('_b', []).append(float(t[1:])); i += 1; continue
        if re.match(r'^[a-zA-Z][a-zA-Z0-9]*$', t) or t.endswith('_C'):
            if t.endswith('_C'):
                vals[t + '_i'] = float(toks[i+1][1:]); vals[t + '_l'] = float(toks[i+2][1:]); i += 3; continue
            vals[t] = float(toks[i+1]); i += 2; continue
        if t.startswith('b'):
            vals.setdefault('_b', []).append(float(t[1:])); i += 1; continue
        i += 1
    for n, v in zip(['hb', 'hh', 'bed'], vals.pop('_b', [])): vals['both_' + n] = v
    d.update(vals); recs.append(d)
# attach totals from JSON
bykey = {}
for si, run in enumerate(sc['runs']):
    for s in run['screws']:
        if not s.get('ok'): continue
        m = s['strategies']
        bykey[(si, s['machine'], s['day'])] = bykey.get((si, s['machine'], s['day']), []) + [(m['both_grey']['metrics']['accumulated_total_um'], m[sf]['metrics']['accumulated_total_um'], m['both_grey']['metrics']['v_u_um'], m[sf]['metrics']['v_u_um'])]
cnt = defaultdict(int)
for r in recs:
    k = (r['seed'], r['key'][0], r['key'][1])
    lst = bykey.get(k, [])
    j = cnt[k]; cnt[k] += 1
    if j < len(lst): r['gtot'], r['wtot'], r['gvu'], r['wvu'] = lst[j]
recs = [r for r in recs if 'gtot' in r]
cols = sys.argv[2].split(',') if len(sys.argv) > 2 else ['tT', 'gT', 'wT', 'rG', 'rW', 'gvu', 'wvu', 'gS', 'tK0', 'gK0', 'dG', 'head_bearing_C_i', 'head_bearing_C_l', 'head_housing_C_i', 'head_housing_C_l', 'bed_middle_C_i', 'bed_middle_C_l', 'both_hb', 'both_hh', 'both_bed']
print(base, 'sf', sf, len(recs), 'cuts')
print('seed  ' + ' '.join(f'{c[:9]:>9s}' for c in cols))
for s in sorted(set(r['seed'] for r in recs)):
    sub = [r for r in recs if r['seed'] == s]
    g = st.median(r['gtot'] for r in sub); w = st.median(r['wtot'] for r in sub)
    print(f'{s} {100*(1-g/w):+6.1f}% ' + ' '.join(f'{st.median(r[c] for r in sub):9.2f}' for c in cols))
lose = [r for r in recs if r['gtot'] > r['wtot']]; win = [r for r in recs if r['gtot'] <= r['wtot']]
for name, sub in (('lose', lose), ('win', win)):
    print(f'{name:4s} n={len(sub):3d} ' + ' '.join(f'{st.median(r[c] for r in sub):9.2f}' for c in cols))
