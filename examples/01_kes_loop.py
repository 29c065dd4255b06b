"""
The KES-FB loop of the hysteretic bending law
=============================================

The Kawabata pure-bending tester (KES-FB) bends a strip from flat to +2.5 cm⁻¹, back through
flat to −2.5 cm⁻¹ and flat again, at 0.5 cm⁻¹/s, and records the moment. The loop it draws is
the fabric's bending hysteresis; the two numbers read off it are the bending rigidity **B**
(the mean slope between 0.5 and 1.5 cm⁻¹) and the loop's width **2HB** at ±1 cm⁻¹.

Here the warp law of the bundled Fabric 1 (Lahey's polyester satin) runs through that profile,
and the moment is split into its elastic, friction and viscous parts
(``M = m κ̈ + d κ̇ + k1 κ + k3 κ³ + M_f``).
"""

import matplotlib.pyplot as plt

from constitutive.kes import kes_profile, kes_values, run_kes
from constitutive.material import load_material
from constitutive.units import to_kes

fabric = load_material("fabric1")           # cases/materials/fabric1.toml, KES units -> SI
law = fabric.warp
print(law)

# %%
# Run the law through the standard profile (1 ms samples) and read B and 2HB off the loop,
# as the tester's software does. Everything inside is SI; KES units are for display.

profile = kes_profile()
loop = run_kes(law, profile)
values = kes_values(loop.kappa, loop.moment)
print(f"B   = {to_kes(values.B, 'B'):.4f} gf·cm²/cm")
print(f"2HB = {to_kes(values.HB2, 'HB2'):.4f} gf·cm/cm")

# %%
# The loop and its parts. The friction part saturates within a short curvature after each
# reversal: that is what leaves a strip bent when the load is gone.

kappa = to_kes(loop.kappa, "curvature")
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4.2))
ax1.plot(kappa, to_kes(loop.moment, "moment"), color="k", lw=1.5, label="total")
ax1.plot(kappa, to_kes(loop.elastic, "moment"), "--", label="elastic k1 κ + k3 κ³")
ax1.set_xlabel("curvature K [cm⁻¹]")
ax1.set_ylabel("moment M [gf·cm/cm]")
ax1.set_title(f"B = {to_kes(values.B, 'B'):.4f}, 2HB = {to_kes(values.HB2, 'HB2'):.4f}")
ax1.legend()
ax2.plot(kappa, to_kes(loop.friction, "moment"), label="friction M_f")
ax2.plot(kappa, to_kes(loop.viscous, "moment"), label="viscous d κ̇")
ax2.set_xlabel("curvature K [cm⁻¹]")
ax2.set_title("the dissipative parts")
ax2.legend()
for ax in (ax1, ax2):
    ax.axhline(0, color="0.6", lw=0.5)
    ax.axvline(0, color="0.6", lw=0.5)
    ax.grid(alpha=0.3)
fig.tight_layout()
plt.show()
