"""Material files as tables (pydantic): laws, membrane, KES sheet, and the material they build.
"""
from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field, model_validator

from constitutive.friction import FrictionParams, ParameterError
from constitutive.law import BendingLaw
from constitutive.material.fabric import DEFAULT_MEMBRANE, FabricMaterial, MaterialError
from constitutive.material.from_kes import material_from_kes
from constitutive.material.kes_sheet import KesSpec, sheet_field
from constitutive.tensile import DEFAULT_TENSILE, MAX_LOAD, TensileCurve
from constitutive.units import to_si

__all__ = ['LawSpec', 'TensileSpec', 'MembraneSpec', 'MaterialSpec', 'KesFabricSpec', 'material_from_spec']


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


class TensileSpec(_Strict):
    """A ``[membrane.tensile_warp]`` or ``[membrane.tensile_weft]`` table: the tensile curve of
    one direction (:class:`constitutive.tensile.TensileCurve`), for a file without the
    ``[kes]`` tensile values that would give it (a law-table file)."""

    strain_at_max: float = Field(gt=0, description="εm = EMT/100, the strain at the maximum load [1].")
    linearity: float = Field(gt=0, lt=2, description="LT, 0 < LT < 2 (below 1: a woven's J-shape) [1].")
    max_load: float = Field(MAX_LOAD, gt=0, description="Fm, the test's maximum load [N/m] "
                                                        "(default the KES-FB1 500 gf/cm).")

    def curve(self) -> TensileCurve:
        return TensileCurve(self.strain_at_max, self.linearity, self.max_load)


#: Direction of each tensile table of ``[membrane]`` and the stiffness it gives.
_TENSILE_TABLES = {"tensile_warp": "E11", "tensile_weft": "E22"}


class MembraneSpec(_Strict):
    """A ``[membrane]`` table (N/m); keys not given come from the ``[kes]`` sheet values (G,
    EMT, LT, WT, E) if any, else :data:`DEFAULT_MEMBRANE`.

    ``E11`` / ``E22`` give a direction's stiffness as a number; ``[membrane.tensile_warp]`` /
    ``[membrane.tensile_weft]`` give it as a tensile curve instead (:class:`TensileSpec`),
    which a drape case takes at its specimen's tension (``[model] membrane_tension``) as it
    does a ``[kes]`` sheet's curve. ``G12`` is the in-plane shear stiffness (engineering shear
    strain, per radian): a law-table file's only way to give a shear other than the default.
    """

    E11: float | None = Field(None, gt=0)
    E22: float | None = Field(None, gt=0)
    nu12: float | None = Field(None, ge=0, lt=1)
    G12: float | None = Field(None, gt=0)
    tensile_warp: TensileSpec | None = None
    tensile_weft: TensileSpec | None = None

    @model_validator(mode="after")
    def _number_or_curve(self):
        for table, key in _TENSILE_TABLES.items():
            if getattr(self, table) is not None and getattr(self, key) is not None:
                raise ValueError(f"@.{key} and [@.{table}] both give {key}: keep one")
        return self

    def curves(self) -> dict:
        """``{"E11" | "E22": TensileCurve}`` of the tensile tables given."""
        return {key: getattr(self, table).curve() for table, key in _TENSILE_TABLES.items()
                if getattr(self, table) is not None}

    def stiffnesses(self) -> dict:
        """E11, E22, nu12, G12 [N/m] given, a curve's as its secant (the stiffness storing its
        energy, as for a sheet's curve)."""
        values = self.model_dump(exclude_none=True, exclude=set(_TENSILE_TABLES))
        values.update({key: curve.secant for key, curve in self.curves().items()})
        return values


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
            given = self.membrane.stiffnesses()
            tables = {key: table for table, key in _TENSILE_TABLES.items()}
            for key in self.kes.membrane()[0]:
                if key in given:
                    where = (f"[membrane.{tables[key]}]" if getattr(self.membrane, key) is None
                             else f"membrane.{key}")
                    raise ValueError(f"{where} and the [kes] values that build it are both "
                                     "given: keep one")
        return self

    def membrane_values(self) -> tuple[dict, dict]:
        """E11, E22, nu12, G12 [N/m] and where each comes from: the ``[kes]`` sheet, the
        ``[membrane]`` table, or the default."""
        values, sources = dict(DEFAULT_MEMBRANE), dict.fromkeys(DEFAULT_MEMBRANE, "default")
        curves = self.membrane.curves()
        for key, value in self.membrane.stiffnesses().items():
            values[key] = value
            sources[key] = (f"material file [membrane] {curves[key].describe()}" if key in curves
                            else "material file [membrane]")
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
        sheet's or the ``[membrane]`` tensile table's, else (where the stiffness is the default) :data:`constitutive.tensile.DEFAULT_TENSILE`,
        whose linear stiffness storing the energy is the default 10⁴ N/m."""
        sheet = {} if self.kes is None else {k: c for k, (c, _) in self.kes.tensile_curves().items()}
        sheet.update(self.membrane.curves())
        sources = self.membrane_values()[1]
        return {key: sheet.get(key, DEFAULT_TENSILE) for key in ("E11", "E22")
                if key in sheet or sources[key] == "default"}


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


class KesFabricSpec(KesSpec):
    """A fabric known from its KES-F sheet: B and 2HB per direction and the weight, optionally
    thickness, shear (G, 2HG, 2HG5) and tensile values (EMT, LT, WT or E per direction). Every
    value is a bare number in the unit a KES sheet prints (B gf·cm²/cm, 2HB gf·cm/cm,
    W mg/cm², T mm, G gf/(cm·deg), 2HG gf/cm, EMT %, WT gf·cm/cm²) or a string with units
    (``weight = "12.38 mg/cm^2"``); values outside the range of woven and knitted fabrics are
    refused, naming the likely unit slip. Bending: :func:`material_from_kes` (k3 = d = 0,
    friction calibrated so that the simulated KES-FB loop gives exactly B and 2HB: first
    order, or second order with ``f2_ratio`` > 0); membrane: from G and the tensile values where given, else E11 = E22 = 1e4 N/m,
    G12 = 50 N/m (summary.json says which)."""

    weight: sheet_field("weight", description="Fabric weight W [mg/cm²] (areal mass "
                                              "= W/100 kg/m²).")
    thickness: sheet_field("thickness", None, "Thickness T [mm] (recorded; the models do not "
                                              "use it).")

    def material_spec(self, name: str, description: str = "", source: str = ""):
        """The same fabric as a material file's tables (:class:`MaterialSpec`)."""
        k = self.model_dump(exclude_none=True)
        weight, thickness = k.pop("weight"), k.pop("thickness", None)
        return MaterialSpec(name=name, description=description, source=source, weight=weight,
                            thickness=thickness, kes=KesSpec(**k))
