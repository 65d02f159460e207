"""The Python package in a few lines: make demo runs it from the repository root
(PYTHONPATH=build/python /usr/bin/python3 examples/python_demo.py); docs/python.md."""
import os
import tempfile

import numpy as np

import pm

# A pointing run: four-column, named-column or TPOINT file (docs/formats.md).
run = pm.read_run("examples/sim_gem.dat")
print(run, "latitude %.1f deg" % np.degrees(run.latitude))

# The paper's L=1 model (22 terms): the coefficients `pmfit fit` gives, to the bit.
res = pm.fit_run(run, order=1)
print(res)
for name, c, e in zip(res.names[:6], res.coefficients, res.errors):
    print("  %-3s %9.2f +- %.2f arcsec" % (name, c * pm.RAD2ARCSEC, e * pm.RAD2ARCSEC))

# Physical terms, as `pmfit fit --add`: the 144-cycle worm and refraction.
res2 = pm.fit_run(run, order=1, add=["ha_periodic:144", "refraction"])
print(res2, "added:", res2.names[-3:])

# Point the telescope: apparent -> encoder and back, vectorised, radians.
model = res2.model
app_ha, app_dec = np.radians([10.0, -35.0, 80.0]), np.radians([20.0, 45.0, -10.0])
enc_ha, enc_dec = model.invert(app_ha, app_dec)
back_ha, back_dec = model.apply(enc_ha, enc_dec)
print("round trip: %.1e rad" % max(np.abs(back_ha - app_ha).max(), np.abs(back_dec - app_dec).max()))
print("model's own error there (1 sigma, arcsec):", res2.pointing_sigma(enc_ha, enc_dec) * pm.RAD2ARCSEC)

# Model files: bit-exact, and `pmfit eval` reads them too.
path = os.path.join(tempfile.mkdtemp(), "mount.pm")
model.save(path)
assert pm.load_model(path) == model

# What did the L=1 model leave out?  `pmfit explain --json` as a dict.
report = pm.explain(run)
for f in report["findings"]:
    print("  found %s: %s" % (f["effect"], f["text"]))

# Errors are exceptions with the library's message (file:line).
try:
    pm.read_run("tests/data/bad_pier.dat")
except pm.FormatError as e:
    print("FormatError:", e)
