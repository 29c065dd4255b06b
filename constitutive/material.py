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
  ``[membrane]`` table (N/m) give them. ``FabricMaterial.membrane_source`` says which.
  E11 and E22 that are not given as numbers keep their tensile curve
  (:attr:`FabricMaterial.tensile`: the sheet's, else
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
"""
from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from constitutive.friction import FrictionParams, ParameterError, friction_path
from constitutive.kes import KesValues, kes_profile, kes_values, run_kes
from constitutive.kes_sheet import KesFabricSpec, KesSpec, sheet_field  # noqa: F401 (re-exported)
from constitutive.law import BendingLaw
from constitutive.tensile import DEFAULT_SECANT, DEFAULT_TENSILE
from constitutive.units import to_si
from constitutive.validation import format_errors

__all__ = ["MaterialError", "FabricMaterial", "load_material", "material_from_kes", "MATERIALS_DIR",
           "DEFAULT_MEMBRANE", "available_materials"]

MATERIALS_DIR = Path(__file__).resolve().parents[1] / "cases" / "materials"

#: Membrane defaults (N/m): woven fabric, nearly inextensible along yarns, soft in shear.
DEFAULT_MEMBRANE = {"E11": DEFAULT_SECANT, "E22": DEFAULT_SECANT, "nu12": 0.0, "G12": 50.0}


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
        the other sheet values given (:meth:`constitutive.kes_sheet.KesSpec.extras_si`).
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
            object.__setattr__(self, "twist_rigidity", math.sqrt(self.warp.k1 * self.weft.k1))
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

def _calibrate(B, HB2, eps_f, eta, profile, f2_ratio=0.0):
    """(k1, friction) such that the simulated loop has slope B and width HB2 (f2 = f2_ratio f1)."""
    if not B > 0:
        raise MaterialError(f"B = {B!r} breaks B > 0")
    if not HB2 >= 0:
        raise MaterialError(f"2HB = {HB2!r} breaks 2HB >= 0")
    if HB2 == 0:
        return B, None
    if not 0.0 <= f2_ratio < 1.0:
        raise MaterialError(f"f2_ratio = {f2_ratio!r} breaks 0 <= f2_ratio < 1 (f1 > f2 >= 0, "
                            "dissipativity, thesis 3.18)")
    # the loop's slope and width are linear in f1 at a fixed ratio f2/f1: calibrate f1 = 1
    unit = FrictionParams(f1=1.0, f2=f2_ratio, eps_f=eps_f, eta=eta)
    s_f, w_f = kes_values(profile.kappa, friction_path(unit, profile.kappa))
    f1 = HB2 / w_f
    k1 = B - f1 * s_f
    if not k1 > 0:
        raise MaterialError(f"2HB = {HB2:g} N is too large for B = {B:g} N·m with eps_f = {eps_f:g} 1/m: "
                            "the friction alone would exceed the slope (k1 > 0 breaks)")
    return k1, FrictionParams(f1=f1, f2=f2_ratio * f1, eps_f=eps_f, eta=eta)


def material_from_kes(name, B_warp, B_weft, HB2_warp, HB2_weft, areal_mass, thickness=None, *,
                      eps_f=20.0, eta=0.5, f2_ratio=0.0, accel_time=None, twist_rigidity=None,
                      description="",
                      source="", membrane_source=None, sheet=None, tensile=None, twist_source="",
                      **membrane) -> FabricMaterial:
    """Build a material from KES summary values only (all arguments SI).

    Parameters
    ----------
    name : str
    B_warp, B_weft : float
        Bending rigidity B [N·m] (KES gf·cm²/cm × 9.80665e-5).
    HB2_warp, HB2_weft : float
        Hysteresis width 2HB [N·m/m] (KES gf·cm/cm × 9.80665e-3).
    areal_mass : float
        [kg/m²] (KES weight mg/cm² / 100).
    thickness : float, optional
        [m].
    eps_f, eta : float
        Friction lengths: a1 = eps_f·eta [1/m] (default 0.1 cm⁻¹) and a2 = eps_f.
    f2_ratio : float
        f2/f1, 0 <= f2_ratio < 1: 0 (default) is first-order friction (Dahl, only a1
        matters); above 0 a second-order law whose moment peaks after a reversal and falls
        to the kinetic value f1 − f2, with the same B and 2HB.
    accel_time : float, optional
        T of the KES profile used for the calibration (default
        :data:`constitutive.kes.DEFAULT_ACCEL_TIME`).
    twist_rigidity : float, optional
        [N·m], default sqrt(k1_warp k1_weft).
    twist_source : str, optional
        Where a given twist rigidity comes from (:attr:`FabricMaterial.twist_source`).
    membrane_source : dict, optional
        Where each membrane value comes from (:attr:`FabricMaterial.membrane_source`).
    sheet : dict, optional
        Other KES sheet values (SI), kept in ``kes`` beside B and 2HB.
    tensile : dict, optional
        Tensile curves behind E11 and E22 (:attr:`FabricMaterial.tensile`).
    **membrane
        E11, E22, nu12, G12 [N/m].

    Returns
    -------
    FabricMaterial
        With ``kes`` holding the given values; see the module docstring for
        the assumptions.

    Examples
    --------
    >>> from constitutive.units import to_si
    >>> m = material_from_kes("x", to_si(0.08, "B"), to_si(0.06, "B"), to_si(0.04, "HB2"),
    ...                       to_si(0.03, "HB2"), areal_mass=to_si(15.0, "weight"))
    >>> v = m.simulated_kes()["warp"]
    >>> round(v.B / to_si(0.08, "B"), 6), round(v.HB2 / to_si(0.04, "HB2"), 6)
    (1.0, 1.0)
    """
    kw = {} if accel_time is None else {"accel_time": accel_time}
    prof = kes_profile(**kw)
    laws = {}
    for key, B, HB2 in (("warp", B_warp, HB2_warp), ("weft", B_weft, HB2_weft)):
        try:
            k1, fr = _calibrate(float(B), float(HB2), eps_f, eta, prof, f2_ratio)
        except (MaterialError, ParameterError) as err:
            raise MaterialError(f"{name}: {key}: {err}") from None
        laws[key] = BendingLaw(k1=k1, friction=fr)
    unknown = set(membrane) - set(DEFAULT_MEMBRANE)
    if unknown:
        raise MaterialError(f"{name}: unknown membrane key(s) {sorted(unknown)}; known: {sorted(DEFAULT_MEMBRANE)}")
    return FabricMaterial(name=name, areal_mass=float(areal_mass), thickness=thickness, warp=laws["warp"],
                          weft=laws["weft"], twist_rigidity=twist_rigidity, twist_source=twist_source,
                          kes={"B_warp": B_warp, "B_weft": B_weft, "HB2_warp": HB2_warp, "HB2_weft": HB2_weft,
                               **(sheet or {})},
                          description=description, source=source,
                          membrane_source=dict(membrane_source or {}), tensile=dict(tensile or {}),
                          **membrane)


# ---------------------------------------------------------------- TOML schema (KES units)

class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)


class LawSpec(_Strict):
    """A ``[warp]`` or ``[weft]`` table (KES units)."""

    k1: float = Field(gt=0, description="gf·cm²/cm")
    k3: float = Field(0.0, ge=0, description="gf·cm⁴/cm")
    d: float = Field(0.0, ge=0, description="gf·cm²·s/cm")
    m: float = Field(0.0, ge=0, description="gf·cm²·s²/cm")
    k1_neg: float | None = Field(None, gt=0, description="gf·cm²/cm, face-down (κ < 0)")
    k3_neg: float | None = Field(None, ge=0, description="gf·cm⁴/cm, face-down (κ < 0)")
    f1: float | None = Field(None, description="gf·cm/cm")
    f2: float | None = Field(None, description="gf·cm/cm")
    eps_f: float | None = Field(None, description="cm⁻¹")
    eta: float | None = Field(None, description="1")

    @model_validator(mode="after")
    def _friction_all_or_none(self):
        given = [k for k in ("f1", "f2", "eps_f", "eta") if getattr(self, k) is not None]
        if given and len(given) < 4:
            missing = sorted({"f1", "f2", "eps_f", "eta"} - set(given))
            raise ValueError(f"friction needs all of f1, f2, eps_f, eta (missing {', '.join(missing)})")
        if given:   # 3.18–3.19 are scale-free: check them in the file's units so the message shows its values
            try:
                FrictionParams(self.f1, self.f2, self.eps_f, self.eta)
            except ParameterError as err:
                raise ValueError(str(err)) from None
        return self

    def to_law(self) -> BendingLaw:
        si = {k: to_si(v, k) for k, v in self.model_dump().items() if v is not None}
        fric = None
        if "f1" in si:
            fric = FrictionParams(*(si.pop(k) for k in ("f1", "f2", "eps_f", "eta")))
        return BendingLaw(friction=fric, **si)


class MembraneSpec(_Strict):
    """A ``[membrane]`` table (N/m); keys not given come from the ``[kes]`` sheet values (G,
    EMT, LT, WT, E) if any, else :data:`DEFAULT_MEMBRANE`."""

    E11: float | None = Field(None, gt=0)
    E22: float | None = Field(None, gt=0)
    nu12: float | None = Field(None, ge=0, lt=1)
    G12: float | None = Field(None, gt=0)


class MaterialSpec(_Strict):
    """A material file: either ``[warp]`` and ``[weft]``, or ``[kes]`` (or all three)."""

    name: str
    description: str = ""
    source: str = ""
    weight: sheet_field("weight", description="Fabric weight W [mg/cm²], as a KES sheet prints it.")
    thickness: sheet_field("thickness", None, "Thickness [mm], as a KES sheet prints it.")
    twist_rigidity: float | None = Field(None, gt=0, description="gf·cm²/cm")
    warp: LawSpec | None = None
    weft: LawSpec | None = None
    kes: KesSpec | None = None
    membrane: MembraneSpec = MembraneSpec()

    @model_validator(mode="after")
    def _laws_or_kes(self):
        if (self.warp is None) != (self.weft is None):
            raise ValueError("give both [warp] and [weft], or neither (then [kes])")
        if self.warp is None and self.kes is None:
            raise ValueError("needs [warp] and [weft] law tables or a [kes] table of summary values")
        if self.kes is not None and self.kes.B_bias is not None and self.twist_rigidity is not None:
            raise ValueError("twist_rigidity and kes.B_bias are both given: keep one")
        if self.kes is not None:
            for key in self.kes.membrane()[0]:
                if getattr(self.membrane, key) is not None:
                    raise ValueError(f"membrane.{key} and the [kes] values that build it are both "
                                     "given: keep one")
        return self

    def membrane_values(self) -> tuple[dict, dict]:
        """E11, E22, nu12, G12 [N/m] and where each comes from: the ``[kes]`` sheet, the
        ``[membrane]`` table, or the default."""
        values, sources = dict(DEFAULT_MEMBRANE), dict.fromkeys(DEFAULT_MEMBRANE, "default")
        for key, value in self.membrane.model_dump(exclude_none=True).items():
            values[key], sources[key] = value, "material file [membrane]"
        if self.kes is not None:
            sheet, why = self.kes.membrane()
            values.update(sheet)
            sources.update(why)
        return values, sources

    def twist(self) -> dict:
        """``twist_rigidity`` [N·m] and ``twist_source`` where the file gives one (the
        ``twist_rigidity`` key, or the ``[kes]`` bias rigidity), else nothing (the default)."""
        if self.twist_rigidity is not None:
            return {"twist_rigidity": to_si(self.twist_rigidity, "B"),
                    "twist_source": "material file twist_rigidity"}
        if self.kes is not None and self.kes.B_bias is not None:
            return {"twist_rigidity": to_si(self.kes.twist_rigidity(), "B"),
                    "twist_source": f"KES B_bias = {self.kes.B_bias:g} gf·cm²/cm: 2 B_bias − (B_warp + B_weft)/2"}
        return {}

    def tensile_curves(self) -> dict:
        """The tensile curve behind E11 and E22 where no number gives them: the ``[kes]``
        sheet's, else (where the stiffness is the default) :data:`constitutive.tensile.DEFAULT_TENSILE`,
        whose linear stiffness storing the energy is the default 10⁴ N/m."""
        sheet = {} if self.kes is None else {k: c for k, (c, _) in self.kes.tensile_curves().items()}
        sources = self.membrane_values()[1]
        return {key: sheet.get(key, DEFAULT_TENSILE) for key in ("E11", "E22")
                if key in sheet or sources[key] == "default"}


def available_materials() -> list[str]:
    """Names of the bundled materials (``cases/materials/*.toml``)."""
    return sorted(p.stem for p in MATERIALS_DIR.glob("*.toml"))


def _resolve(name_or_path) -> Path:
    p = Path(name_or_path)
    if p.suffix == ".toml" or p.exists() or len(p.parts) > 1:
        if not p.is_file():
            raise MaterialError(f"material file {p} does not exist")
        return p
    p = MATERIALS_DIR / f"{name_or_path}.toml"
    if not p.is_file():
        raise MaterialError(f"unknown material {name_or_path!r}; bundled: {', '.join(available_materials())} "
                            "(or give a path to a .toml file)")
    return p


def material_from_spec(spec: MaterialSpec, where: str = "material") -> FabricMaterial:
    """Build a :class:`FabricMaterial` from a validated spec (KES units → SI)."""
    membrane, membrane_source = spec.membrane_values()
    tensile = spec.tensile_curves()
    common = dict(tensile=tensile, areal_mass=to_si(spec.weight, "weight"),
                  thickness=None if spec.thickness is None else to_si(spec.thickness, "thickness"),
                  **spec.twist(),
                  description=spec.description, source=spec.source, membrane_source=membrane_source,
                  **membrane)
    kes_si = None
    if spec.kes is not None:
        k = spec.kes
        kes_si = {"B_warp": to_si(k.B_warp, "B"), "B_weft": to_si(k.B_weft, "B"),
                  "HB2_warp": to_si(k.HB2_warp, "HB2"), "HB2_weft": to_si(k.HB2_weft, "HB2")}
    try:
        if spec.warp is None:
            return material_from_kes(spec.name, **kes_si, eps_f=to_si(spec.kes.eps_f, "eps_f"),
                                     eta=spec.kes.eta, f2_ratio=spec.kes.f2_ratio,
                                     accel_time=spec.kes.accel_time,
                                     sheet=spec.kes.extras_si(), **common)
        laws = {}
        for key in ("warp", "weft"):
            try:
                laws[key] = getattr(spec, key).to_law()
            except ParameterError as err:
                raise MaterialError(f"{key}.{err}") from None
        if kes_si is not None:
            kes_si.update(spec.kes.extras_si())
        return FabricMaterial(name=spec.name, warp=laws["warp"], weft=laws["weft"], kes=kes_si, **common)
    except MaterialError as err:
        raise MaterialError(f"{where}: {err}") from None


def load_material(name_or_path) -> FabricMaterial:
    """Read a material TOML (KES units) and return it in SI.

    Parameters
    ----------
    name_or_path : str or Path
        A bundled name (``"fabric1"``, ``"fabric2"``, ``"kes_example"``; see
        :func:`available_materials`) or the path of a ``.toml`` file.

    Raises
    ------
    MaterialError
        Unknown name, TOML syntax error, unknown key, wrong type or a broken
        rule — the message names the file, the key and the rule.

    Examples
    --------
    >>> load_material("kes_example").warp.friction.f2
    0.0
    >>> load_material("no-such-fabric")
    Traceback (most recent call last):
    ...
    constitutive.material.MaterialError: unknown material 'no-such-fabric'; bundled: fabric1, fabric2, fabric2-table4.14, kes_example (or give a path to a .toml file)
    """
    path = _resolve(name_or_path)
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as err:
        raise MaterialError(f"{path.name}: TOML syntax error: {err}") from None
    try:
        spec = MaterialSpec.model_validate(data)
    except ValidationError as err:
        raise MaterialError("\n".join(f"{path.name}: {line}" for line in
                                      format_errors(err, MaterialSpec).splitlines())) from None
    return material_from_spec(spec, path.name)



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
