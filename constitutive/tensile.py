"""A woven fabric's tensile curve, and the membrane stiffness a drape sees on it.

The KES-FB1 tensile test pulls a strip to the maximum load Fm (standard 500 gf/cm) and
reports the strain there, EMT, the energy WT = ∫₀^εm F dε, and the linearity
LT = WT / (Fm εm / 2) (Kawabata, *The standardization and analysis of hand evaluation*,
2nd ed., 1980). A woven fabric's curve is convex, J-shaped, LT < 1: at low load the crimp
of the yarns interchanges before the yarns themselves stretch, so the slope grows with the
load (Kawabata, Niwa & Kawai, *The finite-deformation theory of plain-weave fabrics*,
J. Text. Inst. 64, 1973).

The curve up to Fm is taken as the power law

    F(ε) = Fm (ε/εm)^m,   m = 2/LT − 1,

the one-parameter family whose linearity is exactly LT (its energy is Fm εm/(m + 1)); LT = 1
is the straight line. A hanging fabric is loaded thousands of times below Fm: the skirt of a
Cusick specimen carries a tenth of a newton per metre against the test's 490 N/m. The linear
membrane of the shell is therefore the curve's tangent at the tension the specimen carries,

    E_t(T) = dF/dε at F = T = (m Fm/εm) (T/Fm)^(1 − 1/m),

not its secant. For LT ≥ 1 (a straight or concave curve) the power law's tangent grows
without bound as the load falls, which no fabric does; the linear stiffness storing WT,
LT Fm/εm, is used there.

Where a sheet gives no tensile values the curve is :data:`DEFAULT_TENSILE`: LT = 0.65, the
middle of woven apparel fabrics' 0.55–0.75 (Kawabata 1980; Kawabata & Niwa, J. Text. Inst. 80,
1989), with the strain at Fm that keeps the linear stiffness storing WT at the project's
long-standing default membrane, 10⁴ N/m (εm = 3.19 %, inside the 2–8 % of woven apparel).
"""
from __future__ import annotations

from dataclasses import dataclass

from constitutive.units import to_si

__all__ = ["TensileCurve", "DEFAULT_LINEARITY", "DEFAULT_SECANT", "DEFAULT_TENSILE", "MAX_LOAD",
           "MAX_LOAD_KES"]

#: KES-FB1 standard maximum load Fm [gf/cm], as a sheet gives it.
MAX_LOAD_KES = 500.0
#: The same in N/m.
MAX_LOAD = to_si(MAX_LOAD_KES, "E_tensile")
#: Linearity LT of a woven fabric whose sheet gives none.
DEFAULT_LINEARITY = 0.65
#: Linear stiffness storing the default curve's tensile energy, LT Fm/εm [N/m].
DEFAULT_SECANT = 1.0e4


@dataclass(frozen=True)
class TensileCurve:
    """The tensile curve F(ε) = Fm (ε/εm)^m of one direction, up to the test's maximum load.

    Parameters
    ----------
    strain_at_max : float
        εm = EMT/100, the strain at the maximum load.
    linearity : float
        LT, 0 < LT < 2 (LT < 1: convex, the woven fabric's J-shape).
    max_load : float
        Fm [N/m].

    Examples
    --------
    >>> c = TensileCurve(0.05, 0.65, 490.0)
    >>> round(c.exponent, 4), round(c.energy / (0.65 * 490.0 * 0.05 / 2), 12)
    (2.0769, 1.0)
    >>> round(c.tangent(490.0) / (c.exponent * 490.0 / 0.05), 12)   # at Fm: m Fm/εm
    1.0
    >>> round(TensileCurve(0.05, 1.0, 490.0).tangent(0.1), 6)       # straight: Fm/εm
    9800.0
    """

    strain_at_max: float
    linearity: float
    max_load: float = MAX_LOAD

    def __post_init__(self):
        if not self.strain_at_max > 0:
            raise ValueError(f"strain at the maximum load = {self.strain_at_max!r} breaks εm > 0")
        if not 0 < self.linearity < 2:
            raise ValueError(f"linearity LT = {self.linearity!r} breaks 0 < LT < 2 "
                             "(m = 2/LT − 1 > 0)")
        if not self.max_load > 0:
            raise ValueError(f"maximum load = {self.max_load!r} breaks Fm > 0")

    @classmethod
    def from_secant(cls, secant: float, linearity: float = DEFAULT_LINEARITY,
                    max_load: float = MAX_LOAD) -> "TensileCurve":
        """The curve of linearity LT whose linear stiffness storing WT is ``secant`` [N/m]."""
        return cls(linearity * max_load / secant, linearity, max_load)

    @property
    def exponent(self) -> float:
        """m = 2/LT − 1."""
        return 2.0 / self.linearity - 1.0

    @property
    def energy(self) -> float:
        """WT = Fm εm/(m + 1) [J/m²] (= LT Fm εm/2)."""
        return self.max_load * self.strain_at_max / (self.exponent + 1.0)

    @property
    def secant(self) -> float:
        """The linear stiffness storing WT at εm: 2 WT/εm² = LT Fm/εm [N/m]."""
        return 2.0 * self.energy / self.strain_at_max**2

    def force(self, strain):
        """F(ε) [N/m] for 0 ≤ ε ≤ εm."""
        return self.max_load * (strain / self.strain_at_max) ** self.exponent

    def tangent(self, tension: float) -> float:
        """dF/dε where F = ``tension`` [N/m]; :attr:`secant` for LT ≥ 1 (see the module)."""
        if not 0 < tension <= self.max_load:
            raise ValueError(f"tension = {tension!r} N/m breaks 0 < T <= Fm = {self.max_load:.4g} N/m")
        if self.linearity >= 1.0:
            return self.secant
        m = self.exponent
        return m * self.max_load / self.strain_at_max * (tension / self.max_load) ** (1.0 - 1.0 / m)

    def describe(self) -> str:
        """The curve in a sheet's terms, for summary.json."""
        return (f"power-law tensile curve, EMT = {100 * self.strain_at_max:.3g} %, "
                f"LT = {self.linearity:.3g}, Fm = {self.max_load:.4g} N/m")


#: The curve of a fabric whose sheet gives no tensile values (module docstring).
DEFAULT_TENSILE = TensileCurve.from_secant(DEFAULT_SECANT)
