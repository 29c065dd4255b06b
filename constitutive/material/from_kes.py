"""A material from a KES-F sheet's B and 2HB: k3 = d = 0, friction calibrated to the loop.

The simulated KES-FB loop of the returned laws gives exactly B and 2HB (first order, or
second order with ``f2_ratio`` > 0).
"""
from __future__ import annotations

from constitutive.friction import FrictionParams, ParameterError, friction_path
from constitutive.kes import kes_profile, kes_values
from constitutive.law import BendingLaw
from constitutive.material.fabric import DEFAULT_MEMBRANE, FabricMaterial, MaterialError

__all__ = ['material_from_kes']


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
