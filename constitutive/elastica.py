"""The Peirce strip as an inextensible elastica with the bending law: clamped, or pushed over a clamp.

A reference for the shell's Peirce cases (``cases/cantilever.toml``, ``cases/peirce_platform.toml``)
that shares nothing with the shell, its contact or its time stepping but the law: the strip is
a row of material segments of length ``ds`` with one curvature each; the part beyond the
clamp hangs under its weight, quasi-statically (no inertia, no viscosity), and each segment's
moment is the law's (:class:`constitutive.law.BendingState`: its friction remembers the
segment's curvature history). Behind the clamp the strip is held flat.

- *Clamped* (:func:`clamped_chord`): the overhang is fixed and the weight grows from nothing
  (the cantilever case's ramp).
- *Pushed* (:func:`pushed_overhang`): the weight is on at the first overhang, then the clamp
  moves back along the strip one segment at a time (the platform case's motion, with a perfect
  grip): each segment is bent hardest as it passes the clamp and then carries a moment that
  falls a little as the overhang curls, so the law's friction keeps it more bent than a
  monotonic loading would.
- *Gripped* (:func:`gripped_overhang`): pushed through a grip that gives, the strip held at its
  rear end and lying up to the edge on a two-sided elastic foundation (as contact holds it, by
  a couple instead of a moment).

For an elastic strip clamped and pushed give the same shape at every overhang (the law has no
memory); with the friction moment the pushed strip is bent more and meets the 41.5° line at a
shorter overhang.

Examples
--------
An elastic strip of fabric 1 clamped at 1.63 cm (the cantilever case's overhang), in 1 mm
segments:

>>> import dataclasses
>>> from constitutive.material import load_material
>>> from constitutive.units import G0
>>> fabric = load_material("fabric1")
>>> elastic = dataclasses.replace(fabric.warp, friction=None)
>>> angle = clamped_chord(elastic, fabric.areal_mass * G0, 0.0163, ds=1e-3, ramp_steps=5)
>>> round(angle, 1)
45.1
"""
from __future__ import annotations

import numpy as np

__all__ = ["Elastica", "GrippedElastica", "clamped_chord", "pushed_overhang", "gripped_overhang"]


def _equilibrium(k, law_moment, load_moment, tol: float, where: str):
    """Curvatures ``k`` at which the law's moment (``law_moment(k) -> (M, dM/dk)``) equals the
    load's (``load_moment(k)``, its Jacobian by forward differences): Newton, each step halved
    until the residual falls."""
    for _ in range(100):
        M, dM = law_moment(k)
        m = load_moment(k)
        r = M - m
        if np.abs(r).max() <= tol * max(float(np.abs(m).max()), 1e-30):
            return k
        h = 1e-6 * max(1.0, float(np.abs(k).max()))
        J = np.diag(dM) - np.column_stack([(load_moment(k + h * e) - m) / h for e in np.eye(len(k))])
        step = np.linalg.solve(J, -r)
        lam = 1.0
        while lam > 1e-4:
            trial = k + lam * step
            if np.abs(law_moment(trial)[0] - load_moment(trial)).max() < np.abs(r).max():
                break
            lam *= 0.5
        k = trial
    raise RuntimeError(f"no equilibrium {where}")


class Elastica:
    """Quasi-static strip under its weight, in segments of one curvature each.

    ``ds`` is rounded so that the segments fill ``length``. Segment ``k`` spans
    ``[k ds, (k + 1) ds]`` from the strip's held end; the clamp is at a segment boundary,
    ``clamp`` segments from that end. The law's state has one point per segment.

    Parameters
    ----------
    law : constitutive.law.BendingLaw
        The strip's bending law (SI).
    weight : float
        Weight per area [N/m²].
    length : float
        The strip's length [m].
    ds : float
        Segment length [m], about.
    """

    def __init__(self, law, weight: float, length: float, ds: float):
        self.law, self.weight = law, float(weight)
        self.n = max(1, int(round(length / ds)))
        self.ds = float(length) / self.n
        self.state = law.new_state((self.n,))
        self.kappa = np.zeros(self.n)

    def shape(self, kappa_free):
        """Segment mid-point positions (x along, z down) of the overhang from the clamp."""
        ds = self.ds
        theta_end = np.cumsum(kappa_free) * ds            # slope at each segment's far end
        theta_mid = theta_end - 0.5 * kappa_free * ds
        # chord of a segment of constant curvature at its mid slope, to second order
        x_end = np.cumsum(np.cos(theta_mid)) * ds
        z_end = np.cumsum(np.sin(theta_mid)) * ds
        return theta_mid, x_end, z_end

    def midpoints(self, kappa):
        """Slope and position (x along, z down) of each segment's mid-point."""
        theta_mid, x_end, z_end = self.shape(kappa)
        return theta_mid, x_end - 0.5 * self.ds * np.cos(theta_mid), z_end - 0.5 * self.ds * np.sin(theta_mid)

    def load_moments(self, theta_mid, x, load):
        """Moment about each segment's mid-point of the loads beyond it [N·m/m]: ``load`` [N/m²]
        per segment, as point loads at the mid-points of the segments beyond and spread over
        the outer half of the segment itself."""
        ds = self.ds
        F = load * ds
        beyond = np.cumsum(F[::-1])[::-1] - F
        beyond_x = np.cumsum((F * x)[::-1])[::-1] - F * x
        return beyond_x - x * beyond + 0.125 * ds * ds * np.cos(theta_mid) * load

    def gravity_moment(self, kappa_free, factor):
        """Moment of the weight beyond each segment's mid-point, about it [N·m/m]."""
        theta_mid, x, _ = self.midpoints(kappa_free)
        return self.load_moments(theta_mid, x, np.full(len(x), factor * self.weight))

    def solve(self, clamp: int, factor: float = 1.0, tol: float = 1e-12):
        """Equilibrium of the overhang beyond segment ``clamp`` under ``factor`` × the weight;
        commits the law's state and returns the overhang's curvatures."""
        free = slice(clamp, self.n)
        held = self.kappa.copy()
        held[:clamp] = 0.0

        def law_moment(k):
            held[free] = k
            M, dM = self.state.trial(held)
            return M[free], dM[free]

        k = _equilibrium(self.kappa[free].copy(), law_moment, lambda k: self.gravity_moment(k, factor),
                         tol, f"at clamp {clamp}, factor {factor}")
        held[free] = k
        self.kappa = held
        self.state.commit(self.kappa)
        return k

    def chord_angle(self, k) -> float:
        """Angle [deg] below the horizontal of the chord from the clamp to the tip."""
        _, x, z = self.shape(k)
        return float(np.degrees(np.arctan2(z[-1], x[-1])))


class GrippedElastica(Elastica):
    """The strip held at its rear end and gripped up to an edge by an elastic foundation.

    Segment 0 is clamped; up to the edge the strip lies on a two-sided elastic foundation of
    stiffness ``grip`` [N/m³] (a force per area ``−grip z``): a grip that holds the slope by a
    couple over a zone, as contact does, instead of a moment at the edge. Every segment is
    free; small slopes in the grip.

    Parameters
    ----------
    law, weight, length, ds
        As for :class:`Elastica`.
    grip : float
        The foundation's stiffness [N/m³].
    every : int
        The grip acts at points ``every`` segments apart, each carrying that many segments'
        share (contact points); 1: everywhere.
    """

    def __init__(self, law, weight: float, length: float, ds: float, grip: float, every: int = 1):
        super().__init__(law, weight, length, ds)
        self.grip = float(grip)
        self.share = np.where(np.arange(self.n) % int(every) == 0, float(every), 0.0)

    def moments(self, kappa, factor, edge):
        """Moment about each segment's mid-point of the weight and the grip's push beyond it."""
        theta_mid, x, z = self.midpoints(kappa)
        load = factor * self.weight - self.grip * self.share * z * (x < edge)      # per area, down
        return self.load_moments(theta_mid, x, load)

    def solve_gripped(self, edge: float, factor: float = 1.0, tol: float = 1e-10):
        """Equilibrium with the edge at ``edge`` under ``factor`` × the weight; commits the law."""
        self.kappa = _equilibrium(self.kappa.copy(), self.state.trial, lambda k: self.moments(k, factor, edge),
                                  tol, f"with the edge at {edge}, factor {factor}")
        self.state.commit(self.kappa)
        return self.kappa

    def chord_from(self, edge: float) -> float:
        """Angle [deg] below the horizontal of the chord from the strip above ``edge`` to the tip."""
        _, x, z = self.midpoints(self.kappa)
        z_edge = float(np.interp(edge, x, z))
        return float(np.degrees(np.arctan2(z[-1] - z_edge, x[-1] - edge)))


def gripped_overhang(law, weight, length, start, end, ds, grip, line=41.5, ramp_steps=20,
                     push_step=2e-5, every: int = 1) -> float:
    """Overhang at which the strip pushed through an elastic grip meets the line.

    Parameters
    ----------
    law : constitutive.law.BendingLaw
        The strip's bending law (SI).
    weight : float
        Weight per area [N/m²].
    length : float
        The strip's length [m], held at its rear end.
    start, end : float
        The first and the last overhang [m]: the grip's edge is drawn back from
        ``length − start`` to ``length − end`` in steps of ``push_step`` [m].
    ds : float
        Segment length [m].
    grip : float
        Stiffness of the two-sided elastic foundation up to the edge [N/m³].
    line : float
        The chord angle to meet [deg], Peirce's 41.5°.
    ramp_steps : int
        Load steps of the weight at the first overhang.
    every : int
        The grip at points ``every`` segments apart (contact points), 1: everywhere.

    Returns
    -------
    float
        The overhang [m] (``length`` less the edge's position) where the chord from the strip
        above the edge to the tip meets ``line`` (linear between steps); NaN if not by ``end``.
    """
    strip = GrippedElastica(law, weight, length, ds, grip, every)
    edge = length - start
    for f in np.linspace(0.0, 1.0, ramp_steps + 1)[1:]:
        strip.solve_gripped(edge, f)
    previous = (start, strip.chord_from(edge))
    for edge in np.arange(length - start - push_step, length - end - 0.5 * push_step, -push_step):
        strip.solve_gripped(edge)
        here = (length - edge, strip.chord_from(edge))
        if here[1] >= line:
            (l0, a0), (l1, a1) = previous, here
            return l0 + (line - a0) * (l1 - l0) / (a1 - a0)
        previous = here
    return float("nan")


def clamped_chord(law, weight, overhang, ds, ramp_steps=20) -> float:
    """Chord angle of the strip clamped at an overhang as its weight grows from nothing.

    Parameters
    ----------
    law : constitutive.law.BendingLaw
        The strip's bending law (SI).
    weight : float
        Weight per area [N/m²].
    overhang : float
        The clamped strip's free length [m].
    ds : float
        Segment length [m].
    ramp_steps : int
        Load steps from no weight to the full weight.

    Returns
    -------
    float
        Angle [deg] below the horizontal of the chord from the clamp to the tip.
    """
    strip = Elastica(law, weight, overhang, ds)
    for f in np.linspace(0.0, 1.0, ramp_steps + 1)[1:]:
        k = strip.solve(0, f)
    return strip.chord_angle(k)


def pushed_overhang(law, weight, start, end, ds, line=41.5, ramp_steps=20) -> float:
    """Overhang at which the strip pushed over a perfect clamp meets the line.

    Parameters
    ----------
    law : constitutive.law.BendingLaw
        The strip's bending law (SI).
    weight : float
        Weight per area [N/m²].
    start, end : float
        The first overhang [m], where the weight is put on, and the last: the clamp moves back
        one segment at a time in between.
    ds : float
        Segment length [m].
    line : float
        The chord angle to meet [deg], Peirce's 41.5°.
    ramp_steps : int
        Load steps of the weight at the first overhang.

    Returns
    -------
    float
        The overhang [m] where the chord from the clamp to the tip meets ``line`` (linear
        between segments); NaN if not by ``end``.
    """
    strip = Elastica(law, weight, end, ds)
    clamp = strip.n - int(round(start / strip.ds))
    for f in np.linspace(0.0, 1.0, ramp_steps + 1)[1:]:
        k = strip.solve(clamp, f)
    previous = (strip.n - clamp) * strip.ds, strip.chord_angle(k)
    while clamp > 0:
        clamp -= 1
        k = strip.solve(clamp)
        here = (strip.n - clamp) * strip.ds, strip.chord_angle(k)
        if here[1] >= line:
            (l0, a0), (l1, a1) = previous, here
            return l0 + (line - a0) * (l1 - l0) / (a1 - a0)
        previous = here
    return float("nan")
