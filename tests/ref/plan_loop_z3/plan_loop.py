import numpy as np, json, sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import *
def make(kind, lat):
    if kind == 'gem':
        return M.GEM(lat, IH=300, ID=-120, CH=40, NP=25, MA=60, ME=-45, TF=10, PE=5, PEG=2, PEph=30)
    return M.AltAz(lat, IA=200, IE=-80, CA=30, NPAE=20, AN=40, AW=-25, TF=12, PE=5, PEG=2, PEph=30)
def horizon_fn(name):
    if name is None: return None, []
    # buildings 40 deg high from az 200 to 340, 15 elsewhere
    return (lambda A: np.where((A > 200) & (A < 340), 40.0, 15.0)), ['--horizon', WORK + '/hz.hrz']
open(WORK + '/hz.hrz','w').write(''.join('%d %d\n' % (a, 40 if 200 < a < 340 else 15) for a in range(0, 360, 2)))
def main(kind, lat, seed, minel, hz, modelargs, outdir, nstart=4, stops=(10, 15, 20, 30), noise=1.0):
    os.makedirs(outdir, exist_ok=True)
    rng = np.random.default_rng(seed)
    mt = make(kind, lat); hfn, hargs = horizon_fn(hz)
    # holdout, noiseless
    A, E = M.sky_points(2000, lat, minel=minel, maxel=85 if kind == 'alt' else 90, rng=rng, horizon=hfn)
    t, d, T, Dd = M.design_obs(mt, A, E, 0.0, rng)
    hold = outdir + '/hold.dat'; M.write_run(hold, mt, t, d, T, Dd)
    # start stars
    A0, E0 = M.sky_points(nstart, lat, minel=minel, maxel=85 if kind == 'alt' else 90, rng=rng, horizon=hfn)
    obs = [list(x) for x in zip(*M.design_obs(mt, A0, E0, noise, rng))]
    res = {}
    planf = outdir + '/plan.dat'
    pargs = ['--min-el', str(minel)] + hargs + modelargs
    while len(obs) < max(stops):
        tt = np.array(obs).T; M.write_run(planf, mt, *tt)
        r = run(['plan', planf, '--next', '1', '--json'] + pargs)
        j = json.loads(r.stdout); tg = j['targets'][0]
        if kind == 'alt':
            o = mt.observe(np.array([tg['azimuth_deg']]), np.array([tg['el_deg']]), None, noise, rng)
        else:
            o = mt.observe(np.array([tg['ha_deg']]), np.array([tg['dec_deg']]), np.array([float(tg['side'])]), noise, rng)
        obs.append([x[0] for x in o])
        n = len(obs)
        if n in stops:
            f = outdir + '/plan%d.dat' % n; M.write_run(f, mt, *np.array(obs).T)
            rms, mx, fj = evaluate(mt, modelargs, f, hold, 'plan')
            res.setdefault('plan', {})[n] = (rms, mx, j['targets'][0]['after_arcsec'])
    # random and grid designs (random: same start stars)
    for n in stops:
        Ar, Er = M.sky_points(n - nstart, lat, minel=minel, maxel=85 if kind == 'alt' else 90, rng=rng, horizon=hfn)
        o2 = M.design_obs(mt, Ar, Er, noise, rng)
        allo = np.hstack([np.array(obs[:nstart]).T, np.array(o2)])
        f = outdir + '/rand%d.dat' % n; M.write_run(f, mt, *allo)
        rms, mx, _ = evaluate(mt, modelargs, f, hold, 'rand'); res.setdefault('rand', {})[n] = (rms, mx)
        # grid: golden spiral, dropping points below horizon and taking more
        k = n
        while True:
            Ag, Eg = golden(k, minel, 85 if kind == 'alt' else 90)
            ok = Eg > (hfn(Ag) if hfn else minel)
            if ok.sum() >= n: break
            k += 1
        Ag, Eg = Ag[ok][:n], Eg[ok][:n]
        o3 = M.design_obs(mt, Ag, Eg, noise, rng)
        f = outdir + '/grid%d.dat' % n; M.write_run(f, mt, *o3)
        rms, mx, _ = evaluate(mt, modelargs, f, hold, 'grid'); res.setdefault('grid', {})[n] = (rms, mx)
    return res
if __name__ == '__main__':
    kind, lat, seed, minel, hz, tag = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), (None if sys.argv[5] == '-' else sys.argv[5]), sys.argv[6]
    modelargs = sys.argv[7:]
    out = WORK + '/runs/' + tag
    st = tuple(int(x) for x in os.environ.get('STOPS', '10,15,20,30').split(','))
    res = main(kind, lat, seed, minel, hz, modelargs, out, nstart=int(os.environ.get('NSTART', 4)), stops=st)
    print(json.dumps({'tag': tag, 'res': res}))
