"""
Bliman–Sorine friction hysteresis
=================================

The law's dry friction is Bliman–Sorine's second-order operator: two first-order (Dahl)
states ``y1``, ``y2`` that relax towards the sign of the motion over curvature lengths
``a1 = ε_f η`` (fast) and ``a2 = ε_f`` (slow), in the path variable ``s = ∫|κ̇| dt``::

    dy/ds = (sign(κ̇) − y) / a,    M_f = f1 y1 − f2 y2.

It depends on the path only, not on the rate. With ``f2 > 0`` the moment overshoots after a
reversal (a static peak ``f_s`` above the sliding value ``f_k = f1 − f2``) before it settles.
Here it is driven along a curvature path with minor loops, and compared with a first-order
(Dahl) operator of the same sliding moment.
"""

import matplotlib.pyplot as plt
import numpy as np

from constitutive.friction import FrictionParams, FrictionState, closed_form_from_rest, friction_path

# Parameters in SI: moments in N·m/m, lengths in 1/m (1 cm⁻¹ = 100 m⁻¹).
second_order = FrictionParams(f1=3.0e-3, f2=2.0e-3, eps_f=40.0, eta=0.2)
first_order = FrictionParams(f1=1.0e-3, f2=0.0, eps_f=40.0, eta=0.2)

# %%
# A path with a large cycle and two minor loops inside it.

t = np.linspace(0.0, 1.0, 4001)
kappa = 250.0 * np.sin(2 * np.pi * t) * (1 - 0.6 * (t > 0.5) * np.sin(8 * np.pi * t) ** 2)
M2 = friction_path(second_order, kappa)
M1 = friction_path(first_order, kappa)

# %%
# ``friction_path`` solves the operator exactly along a sampled path. The finite-element model
# holds the same operator as a state per material point (:class:`~constitutive.friction.FrictionState`):
# ``trial`` evaluates a curvature without changing the state, ``commit`` accepts it. Stepping it
# sample by sample gives the same moments, and from rest it follows the closed form (thesis
# Eq. 3.17) until the first reversal.

state = FrictionState(second_order)
stepped = np.empty_like(kappa)
for i, k in enumerate(kappa):
    stepped[i], _ = state.trial(k)
    state.commit(k)
print(f"state object against the path solution: max difference {np.abs(stepped - M2).max():.1e} N")
first_quarter = t <= 0.25
closed = closed_form_from_rest(second_order, kappa[first_quarter])
print(f"closed form from rest: max difference {np.abs(closed - M2[first_quarter]).max():.1e} N")

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4.2))
ax1.plot(t, kappa / 100, color="0.4")
ax1.set_xlabel("time [s]")
ax1.set_ylabel("curvature K [cm⁻¹]")
ax1.set_title("the curvature path")
ax2.plot(kappa / 100, 1e3 * M2, label="second order (f2 > 0): static peak")
ax2.plot(kappa / 100, 1e3 * M1, "--", label="first order (Dahl), same f_k")
ax2.set_xlabel("curvature K [cm⁻¹]")
ax2.set_ylabel("friction moment [mN·m/m]")
ax2.set_title("hysteresis with minor loops")
ax2.legend(fontsize=8)
for ax in (ax1, ax2):
    ax.grid(alpha=0.3)
fig.tight_layout()
plt.show()
