"""Fabric materials: warp/weft bending laws plus what a shell needs, from TOML files.

A :class:`FabricMaterial` holds, in SI, the areal mass, thickness, the warp
(κ_11) and weft (κ_22) :class:`~constitutive.law.BendingLaw`, the linear twist
rigidity and the membrane stiffness.  Material files are TOML in KES units
(gf, cm, s) and are converted once, here, by :mod:`constitutive.units`.

Defaults (documented, overridable in the file):

* twist rigidity ``D_t = sqrt(k1_warp · k1_weft)``: the value an isotropic
  plate with ν = 0 would have in the energy ``½B1κ11² + ½B2κ22² + D_t κ12²``
  (docs/theory.md §1); fabrics have one, the thesis omitted it.
* membrane (woven fabric: stiff along the yarns, soft in shear):
  ``E11 = E22 = 1.0e4 N/m``, ``ν12 = 0``, ``G12 = 50 N/m``, where neither the
  ``[kes]`` sheet values (G, EMT, LT, WT, E; :mod:`constitutive.kes_sheet`) nor the
  ``[membrane]`` table (N/m; :class:`MembraneSpec`) give them. ``FabricMaterial.membrane_source``
  says which. E11 and E22 that are not given as numbers keep their tensile curve
  (:attr:`FabricMaterial.tensile`: the sheet's, or ``[membrane.tensile_warp]`` /
  ``[membrane.tensile_weft]`` (:class:`TensileSpec`, a curve in a file without a sheet), else
  :data:`constitutive.tensile.DEFAULT_TENSILE`, whose energy-storing stiffness is the
  1.0e4 N/m), and :meth:`FabricMaterial.at_tension` takes them at a drape's tension.

Weight and thickness are read as a KES sheet prints them, mg/cm² and mm (or as strings
with units), and refused outside the range of woven and knitted fabrics
(:mod:`constitutive.kes_sheet`).

Building a material from KES summary values only (:func:`material_from_kes`)
— most labs have just B, 2HB per direction and the weight.  Assumptions:

* ``k3 = 0`` and symmetric face-up/face-down: B is one slope.
* ``d = 0``, ``m = 0``: at the single KES rate the width of the loop cannot
  be split into viscous and frictional parts (2HB ≈ 2 M_f + 2 d v); we give it
  all to rate-independent friction, which is what holds residual curvature
  in quasi-static drape.
* Friction is first order (Dahl) by default: ``f2 = 0``, no static peak (the summary
  values carry no information on one; ``f2_ratio = f2/f1 > 0`` asks for a second-order
  law with one, calibrated to the same B and 2HB), with the short length
  ``a1 = ε_f η = 0.1 cm⁻¹`` (defaults ε_f = 0.2 cm⁻¹, η = 0.5): the moment
  is within 5 % of its sliding value 0.3 cm⁻¹ after a reversal, so the loop
  is nearly a parallelogram of width 2 f1 as in a KES chart.
* ``k1`` and ``f1`` (with ``f2 = f2_ratio · f1``) are then chosen so that the
  simulated KES-FB loop (:func:`constitutive.kes.run_kes` on the standard ±2.5 cm⁻¹
  profile, :func:`constitutive.kes.kes_values`) returns the given B and 2HB.  Both
  are linear in (k1, f1), so this is one 2×2 solve, exact to round-off.

>>> mat = load_material("fabric1")
>>> mat.name, round(mat.areal_mass, 4), round(mat.warp.k1, 11)
('fabric1', 0.1715, 6.2566e-07)

Modules
-------
fabric
    :class:`FabricMaterial` (SI) and its overrides.
spec
    Material files as tables (:class:`MaterialSpec`, :class:`KesFabricSpec`).
from_kes
    :func:`material_from_kes`: laws calibrated to a KES-F sheet's B and 2HB.
kes_sheet
    A KES-F sheet's values, units and plausible ranges.
library
    :func:`load_material`, :func:`available_materials`: the bundled library and files.
"""
from constitutive.material.fabric import DEFAULT_MEMBRANE, FabricMaterial, MaterialError
from constitutive.material.from_kes import material_from_kes
from constitutive.material.kes_sheet import KesSpec, sheet_field
from constitutive.material.library import available_materials, load_material
from constitutive.material.spec import (KesFabricSpec, LawSpec, MaterialSpec, MembraneSpec, TensileSpec,
                                        material_from_spec)

__all__ = ["MaterialError", "FabricMaterial", "DEFAULT_MEMBRANE", "load_material", "available_materials",
           "material_from_kes", "material_from_spec", "MaterialSpec", "LawSpec", "MembraneSpec", "TensileSpec",
           "KesSpec", "KesFabricSpec", "sheet_field"]
