"""The ``[material]`` table of a case: a library material, a file or a KES sheet, with overrides.
"""
from __future__ import annotations

from pydantic import (
    Field,
    model_validator,
)

from constitutive.material import KesFabricSpec
from drape.case.quantities import Q, _rule, _Section

__all__ = ['LawOverride', 'CaseMaterial']


class LawOverride(_Section):
    """Bending-law parameters replacing those of the material (SI; all optional)."""

    k1: Q("N*m", gt=0) | None = None
    """Linear bending rigidity [N·m]."""
    k3: Q("N*m**3", ge=0) | None = None
    """Cubic coefficient [N·m³]."""
    d: Q("N*m*s", ge=0) | None = None
    """Viscous coefficient [N·m·s]."""
    m: Q("N*m*s**2", ge=0) | None = None
    """Curvature-inertia coefficient [N·m·s²]."""
    f1: Q("N", ge=0) | None = None
    """Friction moment of the first (fast) state [N·m/m = N]; must exceed f2."""
    f2: Q("N", ge=0) | None = None
    """Friction moment of the second state [N]."""
    eps_f: Q("1/m", gt=0) | None = None
    """Friction curvature length ε_f [1/m]."""
    eta: float | None = Field(None, gt=0, lt=1)
    """Ratio of the two friction lengths, 0 < η < 1."""

    @model_validator(mode="after")
    def _dissipative(self):
        if self.f1 is not None and self.f2 is not None and not self.f1 > self.f2:
            raise _rule(f"@.f1 = {self.f1} must exceed @.f2 = {self.f2} (dissipativity, 3.18)")
        return self


class CaseMaterial(LawOverride):
    """[material]: the fabric. Give exactly one of ``name``, ``path`` or a ``[material.kes]`` table.

    Law keys at this level (k1, k3, d, m, f1, f2, eps_f, eta) override both directions;
    ``[material.warp]`` / ``[material.weft]`` override one direction and win over them.
    """

    name: str | None = None
    """Material from the library in cases/materials (e.g. ``fabric1``)."""
    path: str | None = None
    """Material file; relative paths are taken from the case file's directory."""
    kes: KesFabricSpec | None = None
    """Inline KES summary values (see [material.kes])."""
    areal_mass: Q("kg/m**2", gt=0) | None = None
    """Override the areal mass ρ_A [kg/m²]."""
    thickness: Q("m", gt=0) | None = None
    """Override the thickness [m]."""
    friction: bool = True
    """``false`` drops the hysteretic friction moment (for friction-free comparisons)."""
    bending_scale: float = Field(1.0, gt=0)
    """Multiplies every bending moment of both laws (k1, k3, d, m, f1, f2; not ε_f, η), after the
    overrides: the same fabric made stiffer or limper (bending length × bending_scale^(1/3))."""
    face_down_ratio: float = Field(1.0, gt=0)
    """Face-up/face-down asymmetry: the face-down (κ < 0) rigidities of both laws are this
    times the face-up ones (k1_neg = ratio · k1, k3_neg = ratio · k3); 1 is symmetric. Turning
    a specimen over is the reciprocal ratio at the scaled rigidity."""
    warp: LawOverride = LawOverride()
    """Overrides of the warp law (acts on κ_xx)."""
    weft: LawOverride = LawOverride()
    """Overrides of the weft law (acts on κ_yy)."""

    @model_validator(mode="after")
    def _one_source(self):
        given = [k for k in ("name", "path", "kes") if getattr(self, k) is not None]
        if len(given) != 1:
            raise _rule(
                "@: give exactly one of name, path or [material.kes]"
                + (f" (got {', '.join(given)})" if given else "")
            )
        friction_keys = ("f1", "f2", "eps_f", "eta")
        if not self.friction:
            for direction in ("warp", "weft"):
                given = [k for k in friction_keys if k in self.law_overrides(direction)]
                if given:
                    raise _rule(f"@.friction = false contradicts the friction override {given[0]}")
        for direction in ("warp", "weft"):
            law = self.law_overrides(direction)
            f1, f2 = law.get("f1"), law.get("f2")
            if f1 is not None and f2 is not None and not f1 > f2:
                k1 = f"@.{direction}.f1" if getattr(self, direction).f1 is not None else "@.f1"
                k2 = f"@.{direction}.f2" if getattr(self, direction).f2 is not None else "@.f2"
                raise _rule(f"{k1} = {f1} must exceed {k2} = {f2} (dissipativity, 3.18)")
        return self

    def law_overrides(self, direction: str) -> dict:
        """Effective overrides for ``direction`` ('warp' or 'weft'): shared keys, then per-direction."""
        shared = {k: getattr(self, k) for k in LawOverride.model_fields}
        own = getattr(self, direction).model_dump(exclude_none=True)
        merged = {k: v for k, v in shared.items() if v is not None}
        merged.update(own)
        return merged


# --------------------------------------------------------------------------- [model]
