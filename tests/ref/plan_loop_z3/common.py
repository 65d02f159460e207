import numpy as np, subprocess, json, os, sys
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mount as M
PMFIT = os.environ.get('PMFIT', os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', '..', 'build', 'pmfit'))
WORK = os.environ.get('WORK', '/tmp/plan_loop_z3')
os.makedirs(WORK, exist_ok=True)
def run(args, check=True):
    # PMFIT_PLAN: another pmfit for plan alone (an older plan, the same fits)
    exe = os.environ.get('PMFIT_PLAN', PMFIT) if args[:1] == ['plan'] else PMFIT
    r = subprocess.run([exe] + args, capture_output=True, text=True)
    if check and r.returncode != 0:
        raise RuntimeError(' '.join(args) + '\n' + r.stderr)
    return r
def golden(n, minel, maxel=90):
    # golden spiral over the cap above minel
    i = np.arange(n) + 0.5
    z = np.sin(minel*M.D) + (np.sin(maxel*M.D) - np.sin(minel*M.D))*i/n
    A = (i*137.50776405) % 360
    return A, np.arcsin(z)/M.D
def evaluate(mount, modelargs, runfile, holdfile, tag):
    mf = runfile + '.pm'
    r = run(['fit', runfile, '--save', mf, '--json'] + modelargs, check=False)
    if r.returncode != 0:
        return None, None, None
    fj = json.loads(r.stdout)
    rf = runfile + '.res'
    run(['eval', mf, holdfile, '--residuals', rf])
    R = np.loadtxt(rf, comments='#')
    e = np.hypot(R[:, 4], R[:, 5])
    return np.sqrt(np.mean(e**2)/2), e.max(), fj
