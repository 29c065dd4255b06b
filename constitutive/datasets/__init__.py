"""Measured KES-FB bending loops: the thesis's polynomials and CSV exports.

Two sources of "measured" moment–curvature loops feed the fit
(:mod:`constitutive.fit`):

* Deng's digitised KES-FB curves [Den94] as printed in the thesis, Appendix B.4:
  one quartic polynomial in curvature per path (Tables B.1–B.12), for the four
  datasets ``fabric1-warp``, ``fabric1-weft``, ``fabric2-warp``,
  ``fabric2-weft`` (:func:`thesis_dataset`).
* CSV exports of a KES-FB instrument: rows of curvature, moment and
  optionally time (:func:`load_kes_csv`).

Both become a :class:`BranchCurves`: the measured moment as a function of
curvature on each of the three paths of the test (0 loading, 1 unloading +
reverse loading, 2 reverse unloading), the turning curvatures K+ and K−, and the
test rate.  :meth:`BranchCurves.sample` lays the measured moment along the
nine-region machine profile (:func:`constitutive.kes.kes_profile`) every 1 ms,
which is how the thesis evaluates its residual (4.17): model and data are
compared at the same instants, the data being looked up on the path the
machine is on.

Turning points of the thesis datasets.  The thesis prints no K±.  The three
path polynomials of a loop must be continuous where the machine turns, so K+ is
the real root of ``P_loading − P_unloading`` and K− the real root of
``P_unloading − P_reverse_unloading`` nearest ±2.5 cm⁻¹ (the KES-FB standard
turning curvature).  They come out as

=============  =======  =======
dataset        K+       K−
=============  =======  =======
fabric1-warp   1.910    −1.949
fabric1-weft   2.323    −2.320
fabric2-warp   2.253    −2.241
fabric2-weft   2.276    −2.270
=============  =======  =======

(cm⁻¹).  The thesis's text agrees where it quotes curvatures (fabric 2 warp:
"a good fit for the region from −2.25 cm⁻¹ to −1.5 cm⁻¹ on the reverse
unloading portion").  Fabric 1 warp is the odd one: Table B.2's constant term
+2.950e-3 puts the unloading path *above* the loading path at κ = 0 (a
clockwise, energy-producing loop near the origin), whereas every other
dataset has a negative unloading moment at κ = 0 as friction requires; with
the opposite sign the turning points would be +2.285/−2.245.  A misprint is
likely, but the tables are kept exactly as printed here.

Measured CSV points are treated the same way: each path's points become a
piecewise-linear M(κ) (duplicates averaged), K± are the extreme curvatures
of the detected paths, and the machine profile between them supplies κ, κ̇, κ̈
at 1 ms — measured curvatures are noisy and differentiating them twice
would be worse than trusting the machine's programmed motion.

Units: SI inside (curvature 1/m, moment per width N·m/m = N, time s); the
polynomials are stored exactly as printed (cm⁻¹ → gf·cm/cm) and converted on
evaluation.

Examples
--------
>>> data = thesis_dataset("fabric1-weft")
>>> round(data.k_plus / 100, 3), round(data.k_minus / 100, 3)
(2.323, -2.32)
>>> loop = data.sample(accel_time=0.1)
>>> loop.kappa.shape == loop.moment.shape == loop.branch.shape
True

Modules
-------
thesis
    The thesis's path polynomials and the loop containers (:class:`KESLoop`).
kes_csv
    CSV exports of a KES-FB instrument: :func:`load_kes_csv`, :func:`write_kes_csv`.
example
    A simulated example export (``python -m constitutive.datasets example``).
"""
from constitutive.datasets.kes_csv import (
                                           detect_branches,
                                           load_dataset,
                                           load_kes_csv,
                                           simulated_export,
                                           write_kes_csv,
)
from constitutive.datasets.thesis import (
                                           CURVATURE_KES,
                                           DATASET_NAMES,
                                           MOMENT_KES,
                                           THESIS_POLYNOMIALS,
                                           BranchCurves,
                                           KESDataError,
                                           KESLoop,
                                           PathPolynomials,
                                           thesis_dataset,
                                           turning_points,
)

__all__ = ["THESIS_POLYNOMIALS", "DATASET_NAMES", "CURVATURE_KES", "MOMENT_KES", "PathPolynomials",
           "KESLoop", "BranchCurves", "KESDataError", "turning_points", "thesis_dataset",
           "detect_branches", "load_kes_csv", "write_kes_csv", "load_dataset", "simulated_export"]
