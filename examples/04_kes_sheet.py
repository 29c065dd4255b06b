"""
A fabric from its KES sheet
===========================

Most labs know a fabric by its KES-F sheet: B and 2HB of warp and weft and the weight W. A
case's ``[material.kes]`` table builds the bending laws from them with
:func:`constitutive.material.material_from_kes`: ``k3 = d = m = 0``, and ``k1`` and the dry
friction chosen so that the simulated KES-FB loop gives exactly the sheet's B and 2HB.

The sheet here is the cotton shirting of ``cases/cusick_kes.toml``. The sheet cannot say
whether the friction has a static peak after a reversal; the default is first order (Dahl,
no peak), ``f2_ratio > 0`` asks for a second-order law with one, calibrated to the same B and
2HB.
"""

import matplotlib.pyplot as plt

from constitutive.kes import kes_profile, run_kes
from constitutive.material import material_from_kes
from constitutive.units import G0, to_kes, to_si

sheet = dict(B_warp=0.085, B_weft=0.062, HB2_warp=0.045, HB2_weft=0.036)   # gf·cm²/cm, gf·cm/cm
weight = 12.5                                                               # mg/cm²
laws = dict(B_warp=to_si(sheet["B_warp"], "B"), B_weft=to_si(sheet["B_weft"], "B"),
            HB2_warp=to_si(sheet["HB2_warp"], "HB2"), HB2_weft=to_si(sheet["HB2_weft"], "HB2"))
first = material_from_kes("shirting", **laws, areal_mass=to_si(weight, "weight"))
second = material_from_kes("shirting, f2/f1 = 0.6", **laws, areal_mass=to_si(weight, "weight"),
                           f2_ratio=0.6)

for fabric in (first, second):
    kes = fabric.simulated_kes()
    print(fabric.name)
    for direction in ("warp", "weft"):
        print(f"  {direction}: B = {to_kes(kes[direction].B, 'B'):.4f} gf·cm²/cm "
              f"(sheet {sheet['B_' + direction]}), 2HB = {to_kes(kes[direction].HB2, 'HB2'):.4f} "
              f"gf·cm/cm (sheet {sheet['HB2_' + direction]})")
c = (laws["B_warp"] / (first.areal_mass * G0)) ** (1 / 3)        # W: weight per area, N/m²
print(f"bending length of the warp (B/W)^(1/3) = {100 * c:.2f} cm")

# %%
# The two warp laws through the KES-FB profile: the same slope and the same width at
# ±1 cm⁻¹, different shapes after each reversal.

profile = kes_profile()
fig, ax = plt.subplots(figsize=(6.5, 4.5))
for fabric, style in ((first, "-"), (second, "--")):
    loop = run_kes(fabric.warp, profile)
    ax.plot(to_kes(loop.kappa, "curvature"), to_kes(loop.moment, "moment"), style,
            label=fabric.name)
ax.set_xlabel("curvature K [cm⁻¹]")
ax.set_ylabel("moment M [gf·cm/cm]")
ax.set_title("warp laws calibrated to B = 0.085, 2HB = 0.045")
ax.grid(alpha=0.3)
ax.legend()
fig.tight_layout()
plt.show()
