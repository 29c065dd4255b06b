"""
Fitting the law to a measured KES-FB loop
=========================================

Deng measured the KES-FB loops of Lahey's two fabrics; the thesis prints them as quartic
polynomials per path (Tables B.1–B.12), bundled as the datasets ``fabric1-warp``,
``fabric1-weft``, ``fabric2-warp`` and ``fabric2-weft``. The fit needs no initial guess: for
fixed friction lengths (ε_f, η) the law is linear in (m, d, k1, k3, f1, f2), which a bounded
linear least-squares solve gives exactly, so only (ε_f, η) are searched, on a grid and then
locally. ``drape fit fabric2-warp`` does the same from the command line.

A CSV export of a KES-FB instrument fits the same way:
:func:`constitutive.datasets.load_kes_csv` reads it (``cases/kes/example_fabric1_weft.csv`` is
an example of the format).
"""

import matplotlib.pyplot as plt

from constitutive.datasets import thesis_dataset
from constitutive.fit import evaluate, fit, model_moment, thesis_law
from constitutive.units import to_kes

data = thesis_dataset("fabric2-warp")
result = fit(data, variant="full")
print(f"residual 4.17: {result.residual:.4g} (gf·cm/cm)²")

# %%
# The thesis's own parameters (Table 4.10), run through the same machine profile, for
# comparison; the fit's parameters in KES units, and B and 2HB of the model loop against the
# data's.

loop = result.loop                       # the measured moment sampled along the profile
thesis, _ = model_moment(thesis_law("fabric2-warp"), loop)
print(f"thesis parameters, same harness: residual {evaluate(thesis_law('fabric2-warp'), loop):.4g}")
record = result.to_json()
for name, value in record["params"].items():
    print(f"{name:6s} {value:12.4e}  {record['units'][name]}")
print(f"B   {record['B']:.4e} (data {record['data_B']:.4e}) gf·cm²/cm")
print(f"2HB {record['2HB']:.4e} (data {record['data_2HB']:.4e}) gf·cm/cm")

fig, ax = plt.subplots(figsize=(6.5, 4.5))
ax.plot(to_kes(loop.kappa, "curvature"), to_kes(loop.moment, "moment"), color="k", lw=3,
        alpha=0.35, label="measured (Deng, thesis Table B)")
ax.plot(to_kes(loop.kappa, "curvature"), to_kes(result.model, "moment"), color="tab:red",
        lw=1.2, label="fitted law")
ax.plot(to_kes(loop.kappa, "curvature"), to_kes(thesis, "moment"), ":", color="tab:blue",
        lw=1.2, label="thesis's parameters")
ax.set_xlabel("curvature K [cm⁻¹]")
ax.set_ylabel("moment M [gf·cm/cm]")
ax.set_title("Fabric 2 warp")
ax.grid(alpha=0.3)
ax.legend()
fig.tight_layout()
plt.show()
