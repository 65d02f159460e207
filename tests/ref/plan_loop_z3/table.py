"""The closed-loop table of docs/model.md ("Which star next", small runs):
an outside probe's own mounts (mount.py; Z3, stop 45), a German and an
alt-az mount at latitude 35, each star observed with 1" noise; from NSTART
random stars, pmfit plan RUN --next 1 and the refit, star by star; against a
golden-spiral lattice and random stars of as many, each design's fit
compared with the truth at 2,000 noiseless places (RMS per axis, arcsec;
RMS over the seeds).

    PMFIT=build/pmfit /usr/bin/python3 tests/ref/plan_loop_z3/table.py

(about 5 minutes on 2 cores; WORK=/tmp/plan_loop_z3 holds the runs;
PMFIT_PLAN=OTHER/pmfit plans with another build, the fits the same.)"""
import json, math, os, subprocess, sys

here = os.path.dirname(os.path.abspath(__file__))
cells = [('gem', 1, 3, (12, 16, 24)), ('gem', 2, 6, (26, 32, 48)),
         ('alt', 1, 3, (12, 16, 24)), ('alt', 2, 6, (26, 32, 48))]
print('| mount | order | stars | plan (closed loop) | golden spiral | random |')
print('|---|---|---|---|---|---|')
for kind, order, nstart, stops in cells:
    got = {}
    for seed in range(1, 7):
        env = dict(os.environ, NSTART=str(nstart), STOPS=','.join(map(str, stops)))
        r = subprocess.run([sys.executable, os.path.join(here, 'plan_loop.py'), kind, '35', str(seed),
                            '15', '-', 't%s%d_%d' % (kind, order, seed), '--order', str(order)],
                           capture_output=True, text=True, env=env)
        if r.returncode != 0:
            sys.exit('%s order %d seed %d failed:\n%s' % (kind, order, seed, r.stderr[-2000:]))
        res = json.loads(r.stdout)['res']
        for design, per_n in res.items():
            for n, v in per_n.items():
                got.setdefault((int(n), design), []).append(v[0])
    def cell(v):
        ok = [x for x in v if x is not None] # (None: the design's fit failed)
        t = '%.2f"' % math.sqrt(sum(x * x for x in ok) / len(ok)) if ok else '-'
        return t + (' (%d of %d fits failed)' % (len(v) - len(ok), len(v)) if len(ok) < len(v) else '')
    for n in stops:
        print('| %s | %d | %d | %s | %s | %s |' % ('German' if kind == 'gem' else 'alt-az', order, n,
                                                cell(got[(n, 'plan')]), cell(got[(n, 'grid')]),
                                                cell(got[(n, 'rand')])))
