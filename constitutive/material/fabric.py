"""A fabric in SI: areal mass, thickness, warp and weft laws, twist and membrane, and overrides.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from constitutive.defaults import DEFAULT_MEMBRANE, default_twist_rigidity
from constitutive.friction import FrictionParams
from constitutive.kes import kes_profile, kes_values, run_kes
from constitutive.law import BendingLaw

__all__ = ['MaterialError', 'FabricMaterial', 'DEFAULT_MEMBRANE']




class MaterialError(ValueError):
    """A material file or value breaks a rule (the message names the key and the rule)."""


@dataclass(frozen=True, eq=False)
class FabricMaterial:
    """A fabric for the plate/shell models, all SI.

    Parameters
    ----------
    name : str
    areal_mass : float
        ρ_A [kg/m²] (KES weight mg/cm² / 100).
    thickness : float or None
        [m] (for output and contact only; bending comes from the laws).
    warp, weft : BendingLaw
        Laws for κ_11 (warp, x) and κ_22 (weft, y).
    twist_rigidity : float or None
        D_t [N·m]; ``None`` → ``sqrt(k1_warp k1_weft)``.
    E11, E22, G12 : float
        Membrane stiffnesses [N/m]; ``nu12`` Poisson's ratio.
    kes : dict or None
        KES summary values if known (SI): ``B_warp, B_weft, HB2_warp, HB2_weft`` and those of
        the other sheet values given (:meth:`constitutive.material.kes_sheet.KesSpec.extras_si`).
    membrane_source : dict
        Where each of E11, E22, nu12, G12 comes from (text); a key missing means "given in
        code" (or the default, if it has the default value).
    twist_source : str
        Where a given ``twist_rigidity`` comes from (text, for summary.json).
    tensile : dict
        ``{"E11": TensileCurve, "E22": ...}`` for the directions whose stiffness comes from a
        tensile curve (a KES sheet's, or :data:`constitutive.tensile.DEFAULT_TENSILE`);
        :meth:`at_tension` linearises them.
    membrane_tension : float or None
        The tension [N/m] at which E11 and E22 were taken on their curves (:meth:`at_tension`);
        ``None``: the linear stiffness storing the tensile energy.

    Examples
    --------
    >>> m = FabricMaterial("demo", 0.2, None, BendingLaw(k1=4e-6), BendingLaw(k1=1e-6))
    >>> m.twist_rigidity, m.G12
    (2e-06, 50.0)
    """

    name: str
    areal_mass: float
    thickness: float | None
    warp: BendingLaw
    weft: BendingLaw
    twist_rigidity: float | None = None
    E11: float = DEFAULT_MEMBRANE["E11"]
    E22: float = DEFAULT_MEMBRANE["E22"]
    nu12: float = DEFAULT_MEMBRANE["nu12"]
    G12: float = DEFAULT_MEMBRANE["G12"]
    kes: dict | None = None
    description: str = ""
    source: str = ""
    membrane_source: dict = field(default_factory=dict)
    tensile: dict = field(default_factory=dict)
    membrane_tension: float | None = None
    twist_source: str = ""
    _twist_default: bool = field(default=False, init=False, repr=False)

    def __post_init__(self):
        def need(key, ok, rule):
            if not ok:
                raise MaterialError(f"{self.name}: {key} = {getattr(self, key)!r} breaks {rule}")
        need("areal_mass", self.areal_mass > 0, "areal_mass > 0")
        need("thickness", self.thickness is None or self.thickness > 0, "thickness > 0")
        for key in ("warp", "weft"):
            need(key, isinstance(getattr(self, key), BendingLaw), "must be a BendingLaw")
            need(key, np.ndim(getattr(self, key).k1) == 0, "scalar law parameters (one material)")
        if self.twist_rigidity is None:
            object.__setattr__(self, "twist_rigidity", default_twist_rigidity(self.warp, self.weft))
            object.__setattr__(self, "_twist_default", True)
        need("twist_rigidity", self.twist_rigidity > 0, "twist_rigidity > 0")
        for key in ("E11", "E22", "G12"):
            need(key, getattr(self, key) > 0, f"{key} > 0")
        need("nu12", 0 <= self.nu12 and self.nu12**2 * self.E22 / self.E11 < 1,
             "0 <= nu12 and nu12² E22/E11 < 1 (positive definite membrane stiffness)")
        need("tensile", set(self.tensile) <= {"E11", "E22"}, "keys among E11, E22")

    def at_tension(self, tension: float) -> "FabricMaterial":
        """Copy whose E11 and E22 are their tensile curves' tangents at ``tension`` [N/m].

        Directions without a curve (a stiffness given as a number) keep theirs. The tension
        is the one the specimen carries (e.g. :func:`drape.analyses.drape_coefficient.skirt_tension`): a fabric's
        curve is convex, so at a drape's load its tangent lies far below the stiffness that
        stores the test's energy (:mod:`constitutive.tensile`).

        Examples
        --------
        >>> from constitutive.tensile import DEFAULT_TENSILE
        >>> m = FabricMaterial("demo", 0.2, None, BendingLaw(k1=4e-6), BendingLaw(k1=4e-6),
        ...                    tensile={"E11": DEFAULT_TENSILE, "E22": DEFAULT_TENSILE})
        >>> d = m.at_tension(0.05)
        >>> round(d.E11), d.E22 == d.E11, d.G12
        (272, True, 50.0)
        """
        if not self.tensile:
            return self
        values = {key: curve.tangent(tension) for key, curve in self.tensile.items()}
        source = {key: f"tangent at T = {tension:.4g} N/m of the {curve.describe()} "
                       f"({self.membrane_source.get(key, 'default')})"
                  for key, curve in self.tensile.items()}
        return self.replace(membrane_source={**self.membrane_source, **source},
                            membrane_tension=float(tension), **values)

    def describe(self) -> dict:
        """What summary.json records of the material (SI): areal mass, thickness, twist
        rigidity, each membrane stiffness with its source, and the KES sheet values given.

        >>> m = FabricMaterial("demo", 0.2, None, BendingLaw(k1=4e-6), BendingLaw(k1=1e-6), G12=80.0)
        >>> d = m.describe()["membrane"]
        >>> d["G12"]["source"], d["E11"]["source"]
        ('given', 'default')
        """
        membrane = {}
        for key, default in DEFAULT_MEMBRANE.items():
            value = float(getattr(self, key))
            source = self.membrane_source.get(key, "default" if value == default else "given")
            membrane[key] = {"value": value, "unit": "1" if key == "nu12" else "N/m", "source": source}
        return {"areal_mass_kg_per_m2": float(self.areal_mass),
                "thickness_m": None if self.thickness is None else float(self.thickness),
                "twist_rigidity_Nm": float(self.twist_rigidity),
                "twist_rigidity_source": "default sqrt(k1_warp k1_weft)" if self._twist_default
                                         else self.twist_source or "given",
                "membrane": membrane,
                "membrane_tension_N_per_m": self.membrane_tension,
                "kes_si": {k: float(v) for k, v in (self.kes or {}).items()}}

    def simulated_kes(self, **profile_kw) -> dict:
        """B and 2HB of each direction from a simulated KES-FB test (SI)."""
        prof = kes_profile(**profile_kw)
        out = {}
        for key, law in (("warp", self.warp), ("weft", self.weft)):
            loop = run_kes(law, prof)
            out[key] = kes_values(loop.kappa, loop.moment)
        return out

    def with_overrides(self, laws: dict | None = None, friction: bool = True,
                       bending_scale: float = 1.0, **changes) -> "FabricMaterial":
        """Copy with a case's overrides applied (SI values), validated again.

        Parameters
        ----------
        laws : dict, optional
            ``{"warp": {...}, "weft": {...}}``: law parameters to replace in each direction
            (``k1``, ``k3``, ``d``, ``m``, and the friction keys ``f1, f2, eps_f, eta``; a law
            without friction needs all four of those).
        friction : bool
            False drops the friction of both laws.
        bending_scale : float
            Every moment of both laws multiplied by it (:meth:`BendingLaw.scaled`).
        **changes
            Other fields (``areal_mass``, ``thickness``, ``twist_rigidity``, membrane).

        Returns ``self`` when nothing changes.

        Examples
        --------
        >>> m = FabricMaterial("demo", 0.2, None, BendingLaw(k1=4e-6), BendingLaw(k1=1e-6))
        >>> m.with_overrides({"weft": {"k1": 4e-6}}).twist_rigidity
        4e-06
        """
        laws = laws or {}
        for direction in ("warp", "weft"):
            over = laws.get(direction) or {}
            law = getattr(self, direction)
            if over or not friction:
                law = _override_law(law, over, friction, direction)
            if bending_scale != 1.0:
                law = law.scaled(bending_scale)
            if law is not getattr(self, direction):
                changes[direction] = law
        changes = {k: v for k, v in changes.items() if v is not None}
        if not changes:
            return self
        if "twist_rigidity" in changes:
            changes["twist_source"] = "case [model] twist_rigidity"
        overridden = [k for k in DEFAULT_MEMBRANE if k in changes]
        if overridden:
            changes["membrane_source"] = {**self.membrane_source,
                                          **dict.fromkeys(overridden, "case [model.membrane]")}
            changes["tensile"] = {k: c for k, c in self.tensile.items() if k not in overridden}
        try:
            return self.replace(**changes)
        except ValueError as err:
            raise MaterialError(f"material after the case's overrides: {err}") from None

    def replace(self, **changes) -> "FabricMaterial":
        """Copy with some fields changed (SI values), validated again."""
        if self._twist_default:          # a defaulted twist rigidity follows new laws
            changes.setdefault("twist_rigidity", None)
        return dataclasses.replace(self, **changes)


# ---------------------------------------------------------------- from KES summary values


_FRICTION_KEYS = ("f1", "f2", "eps_f", "eta")


def _override_law(law: BendingLaw, over: dict, friction: bool, direction: str) -> BendingLaw:
    """``law`` with the overridden parameters (and friction dropped if ``friction`` is False)."""
    over = dict(over)
    new_friction = {k: over.pop(k) for k in _FRICTION_KEYS if k in over}
    fr = law.friction
    if not friction:
        fr = None
    elif new_friction:
        base = {} if fr is None else {k: getattr(fr, k) for k in _FRICTION_KEYS}
        base.update(new_friction)
        missing = [k for k in _FRICTION_KEYS if k not in base]
        if missing:
            raise MaterialError(
                f"material.{direction}: the material has no friction, so an override must give "
                f"all of f1, f2, eps_f, eta (missing {', '.join(missing)})")
        try:
            fr = FrictionParams(**base)
        except ValueError as err:
            raise MaterialError(f"material.{direction} after the case's overrides: {err}") from None
    try:
        return dataclasses.replace(law, friction=fr, **over)
    except ValueError as err:
        raise MaterialError(f"material.{direction} after the case's overrides: {err}") from None
