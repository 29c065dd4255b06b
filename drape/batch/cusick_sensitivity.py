"""The factors of a Cusick drape's sensitivity study: what moves its DC and node count.

The levels are taken around the base case (any Cusick case with ``[material.kes]``). The
default base, and the case the notes below speak of, is ``cases/validation/wool_tropical.toml``
(Matsudaira et al. 2015: B = 0.067 gf·cm²/cm, 2HB = 0.033 gf·cm/cm, W = 16.29 mg/cm², 25.4 cm
specimen on a 12.7 cm disc; measured DC 49.8 %, 5 nodes). Its bending length is c = (B/W)^(1/3) = 1.6 cm against a
6.35 cm overhang, so the drape's curvatures are of order 1/c ≈ 0.6 cm⁻¹. Every factor below
moves one thing away from that case, to a low and a high level (or to one alternative),
chosen from physics or the literature as stated:

``friction_length``  ``material.kes.eps_f``, default 0.2 cm⁻¹ (η = 0.5: the first-order length
    a1 = ε_f η = 0.1 cm⁻¹, sliding within 0.3 cm⁻¹ of a reversal). Low 0.05 cm⁻¹
    (a1 = 0.025 cm⁻¹: practically Coulomb friction). High 0.8 cm⁻¹ (a1 = 0.4 cm⁻¹: sliding
    only 1.2 cm⁻¹ after a reversal, beyond the drape's curvatures, so folds bend mostly on
    the friction's stiff branch; the thesis's fits of Deng's KES loops have ε_f ≈ 0.73 cm⁻¹,
    cases/materials/fabric1.toml). Both still give exactly the sheet's B and 2HB. At first
    order η enters only through a1 = ε_f η, so an η level would repeat this factor; η's own
    effect comes with f2 > 0 (next factor).
``friction_order``  ``material.kes.f2_ratio``, default 0 (first order, Dahl: no static peak).
    f2/f1 = 0.3 and 0.7 at η = 0.5, calibrated to the same B and 2HB: after each reversal the
    moment peaks 3 % and 41 % above the kinetic moment f1 − f2 (thesis 3.10-3.11), spanning
    the excess of static over kinetic friction reported for fibre assemblies (up to some tens
    of per cent; Morton & Hearle, *Physical properties of textile fibres*).
``friction_off``  ``material.friction = false``: the calibrated elastic part alone (k1 ≈ B).
``membrane_tension``  ``model.membrane_tension``: the tension at which the membrane is taken
    on the tensile curve (no tensile values on the sheet: LT = 0.65, εm = 3.19 %), default the
    skirt's mean tension T̄ = 0.056 N/m (E11 = E22 ≈ 290 N/m). Low T̄/3, high 3 T̄ (E × 0.57 and
    × 1.77, as E ∝ T^(1 − 1/m)): the tension along a meridian runs from 2.7 T̄ at the disc's edge
    to nothing at the hem, and the factor also spans the sheets' spread of LT and EMT.
``shear_G12``  ``material.kes.G``, default G12 = 50 N/m (G ≈ 0.89 gf/(cm·deg)). Low
    G = 0.3 gf/(cm·deg) (G12 ≈ 17 N/m), high 2.7 gf/(cm·deg) (G12 ≈ 152 N/m): factor 3 either
    way, inside the 0.2-5 gf/(cm·deg) of apparel fabrics (constitutive/material/kes_sheet.py). Folds
    of a circular specimen need in-plane shear (a trellised weave), so G12 may set the node
    count.
``perturbation_amplitude``  ``load.perturbation.amplitude``, default 0.02 of the weight.
    0.005 and 0.08 (×1/4, ×4).
``perturbation_spectrum``  ``load.perturbation.k_min``..``k_max``, default 2-12. 2-6 (long
    waves only: no mode with the 8 simulated folds) and 6-18 (short waves only: no mode with
    the 5 measured folds). If the node count follows the spectrum, the imperfection, not the
    fabric, chooses it.
``perturbation_duration``  ``load.perturbation.duration``, default 2 s (over the lowering).
    0.4 s (over while the specimen is still being let down) and 6 s (still pushing for 4 s
    after the weight is all on).
``perturbation_seed``  ``load.perturbation.seed``, default 0. Seeds 1 and 2: not low and
    high, the bar is the seed noise against which the other bars are read. Left out with
    ``--seeds N > 1``, where the base's spread over its seeds is drawn as a band instead.
``gravity_ramp``  ``load.gravity.ramp_time``, default 2 s (the specimen let down onto the
    disc: 4 × the 0.5 s swing period 2π√(L/g) of the 6.35 cm overhang as a pendulum, so the
    fabric follows the load). Low 0.2 s (hardly slower than free fall over the overhang,
    √(2·0.0635 m/g) ≈ 0.11 s: a drop). High 6 s (a slower hand). The perturbation keeps its
    2 s.
``agitation``  ``[load.agitation]``, default none (the drape read as it settles). Some
    testers tap or shake the disc before reading, to free the folds that friction holds. The
    disc is shaken vertically after the lowering, 3 cycles at 2 Hz (the skirt's swing
    frequency): peak 0.1 g (a tap, 13 mm stroke) and 0.3 g (a firm shake, 38 mm stroke).
``air_drag``  ``model.damping.air_drag``, default 0.3 N·s/m³: still air's drag ½ ρ_air C_d v²
    (C_d ≈ 1.2) linearised at v ≈ 0.4 m/s, mass damping 0.3/ρ_A ≈ 1.8 1/s for this 163 g/m²
    fabric (damping ratio ≈ 0.08 of the overhang's pendulum mode ω ≈ √(g/L) ≈ 12 rad/s).
    Low 0.1 (v ≈ 0.13 m/s), high 3 N·s/m³ (18 1/s, ratio ≈ 0.8: the heavy numerical damping
    the Cusick cases used before they were let down in air).
``air_drag_form``  ``model.damping.drag_coefficient``: still air's quadratic drag
    ½ ρ_air C_d |v·n| v·n normal to the fabric (C_d = 1.2, a plate broadside) in place of the
    linear drag: no reference speed, much drag for a falling fold and almost none in the creep.
``mesh``  Low: 2/3 of the base's radial and circumferential divisions, around the nearest twice
    a prime (4 × 46 for 6 × 74; the recorded study: 4 × 48 for 6 × 72), same grading. High:
    ``mesh.refine = 1`` (12 × 148, every triangle in four; the
    convergence level, about 4 × the cost).

:func:`factors` builds them around a loaded case, :func:`study_factors` around a case file as
a study asks for them; :func:`drape.batch.sensitivity.run_study` runs them.
"""
from __future__ import annotations

from constitutive.bundled import cases_dir
from drape.batch.sensitivity import Factor, Level, StudyError
from drape.case.build import build_material
from drape.case.case import CaseError, load_case
from meshes.annulus import twice_a_prime

__all__ = ["BASE_CASE", "coarser_mesh", "factors", "study_factors"]

#: The default base case: the wool of the validation set.
BASE_CASE = cases_dir("validation", "wool_tropical.toml")


def coarser_mesh(mesh) -> dict:
    """Keys of the low mesh level: 2/3 of the divisions (around: the nearest twice a prime, a
    grid that favours no fold count), else 1.5 × the size."""
    if mesh.n_radial is None or mesh.n_circumferential is None:
        return {"mesh.target_size": repr(1.5 * mesh.target_size)}
    n_c = twice_a_prime(2 * mesh.n_circumferential / 3)
    return {"mesh.n_radial": str(max(1, round(2 * mesh.n_radial / 3))),
            "mesh.n_circumferential": str(n_c)}


def factors(case) -> list[Factor]:
    """The study's factors around a Cusick case (the module docstring says why each level).

    Parameters
    ----------
    case : drape.case.case.Case
        A loaded Cusick case with ``[material.kes]``, ``[load.gravity]`` and
        ``[load.perturbation]``.

    Returns
    -------
    list of Factor

    Raises
    ------
    StudyError
        The case is no such Cusick case, or takes no membrane tension.
    """
    kes, pert = case.material.kes, case.load.perturbation
    if kes is None or pert is None or case.load.gravity is None or case.case.analysis != "cusick":
        raise StudyError("the base case must be a Cusick case with [material.kes], "
                         "[load.gravity] and [load.perturbation]")
    mesh = case.mesh
    material = build_material(case)       # SI, its membrane taken at the case's tension
    if material.membrane_tension is None:
        raise StudyError("the base case takes no membrane tension (model.membrane_tension = 'secant')")
    tension = material.membrane_tension
    low_mesh = coarser_mesh(mesh)
    low_label = (f"{low_mesh['mesh.n_radial']} × {low_mesh['mesh.n_circumferential']}"
                 if "mesh.n_radial" in low_mesh else f"size {low_mesh['mesh.target_size']} m")
    base_mesh = (f"{mesh.n_radial} × {mesh.n_circumferential}" if mesh.n_radial else
                 f"size {mesh.target_size} m") + (f", refine {mesh.refine}" if mesh.refine else "")
    return [
        Factor("friction_length", "friction length ε_f", f"{kes.eps_f:g} cm⁻¹", (
            Level("low", "0.05 cm⁻¹", {"material.kes.eps_f": "0.05"}, "low"),
            Level("high", "0.8 cm⁻¹", {"material.kes.eps_f": "0.8"}, "high"))),
        Factor("friction_order", "second-order friction f2/f1", f"{kes.f2_ratio:g}", (
            Level("low", "0.3", {"material.kes.f2_ratio": "0.3"}, "low"),
            Level("high", "0.7", {"material.kes.f2_ratio": "0.7"}, "high"))),
        Factor("friction_off", "friction", "from 2HB", (
            Level("off", "off", {"material.friction": "false"}, "low"),)),
        Factor("membrane_tension", "membrane taken at tension T", f"{tension:.3g} N/m", (
            Level("low", f"{tension / 3:.3g} N/m", {"model.membrane_tension": f"{tension / 3!r}"}, "low"),
            Level("high", f"{3 * tension:.3g} N/m", {"model.membrane_tension": f"{3 * tension!r}"},
                  "high"))),
        Factor("shear_G12", "in-plane shear G12", f"{material.G12:g} N/m", (
            Level("low", "17 N/m", {"material.kes.G": "0.3"}, "low"),
            Level("high", "152 N/m", {"material.kes.G": "2.7"}, "high"))),
        Factor("perturbation_amplitude", "perturbation amplitude", f"{pert.amplitude:g}", (
            Level("low", "0.005", {"load.perturbation.amplitude": "0.005"}, "low"),
            Level("high", "0.08", {"load.perturbation.amplitude": "0.08"}, "high"))),
        Factor("perturbation_spectrum", "perturbation modes k", f"{pert.k_min}–{pert.k_max}", (
            Level("low", "2–6", {"load.perturbation.k_min": "2",
                                 "load.perturbation.k_max": "6"}, "low"),
            Level("high", "6–18", {"load.perturbation.k_min": "6",
                                   "load.perturbation.k_max": "18"}, "high"))),
        Factor("perturbation_duration", "perturbation duration", f"{pert.duration:g} s", (
            Level("low", "0.4 s", {"load.perturbation.duration": "0.4"}, "low"),
            Level("high", "6 s", {"load.perturbation.duration": "6.0"}, "high"))),
        Factor("perturbation_seed", "perturbation seed", f"{pert.seed}", (
            Level("s1", "seed 1", {"load.perturbation.seed": "1"}, "low"),
            Level("s2", "seed 2", {"load.perturbation.seed": "2"}, "high"))),
        Factor("gravity_ramp", "gravity ramp time", f"{case.load.gravity.ramp_time:g} s", (
            Level("drop", "0.2 s", {"load.gravity.ramp_time": "0.2"}, "low"),
            Level("slower", "6 s", {"load.gravity.ramp_time": "6.0"}, "high"))),
        Factor("agitation", "disc shaken before reading (3 cycles, 2 Hz)", "not shaken", (
            Level("gentle", "0.1 g", {"load.agitation.acceleration": "0.1"}, "low"),
            Level("firm", "0.3 g", {"load.agitation.acceleration": "0.3"}, "high"))),
        Factor("air_drag", "air drag c", f"{case.model.damping.air_drag:g} N·s/m³", (
            Level("low", "0.1 N·s/m³", {"model.damping.air_drag": "0.1"}, "low"),
            Level("high", "3 N·s/m³", {"model.damping.air_drag": "3"}, "high"))),
        Factor("air_drag_form", "air drag form", "linear", (
            Level("quadratic", "quadratic, C_d 1.2", {"model.damping.air_drag": "0",
                                                     "model.damping.drag_coefficient": "1.2"},
                  "high"),)),
        Factor("mesh", "mesh", base_mesh, (
            Level("coarse", low_label, low_mesh, "low"),
            Level("refine1", f"refine {mesh.refine + 1}",
                  {"mesh.refine": str(mesh.refine + 1)}, "high"))),
    ]


def study_factors(case_path, overrides=(), seeds: int = 1, names=None) -> list[Factor]:
    """The factors of a study around the case file ``case_path``.

    Parameters
    ----------
    case_path : path
        A Cusick case file (:func:`factors`).
    overrides : sequence of str
        ``--set`` items applied to the case (and to every run of the study).
    seeds : int
        Perturbation seeds per level: with more than one, the ensemble's own spread replaces
        the ``perturbation_seed`` factor, which is left out.
    names : list of str, optional
        Only these factors, in the study's order (default: every one).

    Raises
    ------
    StudyError
        The case does not load or is no Cusick case of :func:`factors`, or a name is unknown.
    """
    try:
        case = load_case(case_path, list(overrides))
    except CaseError as exc:
        raise StudyError(f"case {case_path}: {' '.join(str(exc).split())}") from None
    chosen = factors(case)
    if seeds > 1:
        chosen = [f for f in chosen if f.name != "perturbation_seed"]
    if names:
        known = {f.name for f in chosen}
        unknown = [w for w in names if w not in known]
        if unknown:
            raise StudyError(f"--factors: unknown {', '.join(unknown)}; known: {', '.join(sorted(known))}")
        chosen = [f for f in chosen if f.name in names]
    return chosen
