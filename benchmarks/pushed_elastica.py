"""The Peirce strip as an inextensible elastica with the bending law: clamped, or pushed over a clamp.

A reference for the platform Peirce case that shares nothing with the shell but the law: the
strip is a row of material segments of length ``ds`` with one curvature each; the part beyond
the clamp hangs under its weight, quasi-statically (no inertia, no viscosity), and each
segment's moment is the law's (``constitutive.BendingState``: its friction remembers the
segment's curvature history). Behind the clamp the strip is held flat.

- *Clamped*: the overhang is fixed and the weight grows from nothing (the cantilever case's ramp).
- *Pushed*: the weight is on at the first overhang, then the clamp moves back along the strip
  one segment at a time (the platform case's motion, with a perfect grip): each segment is
  bent hardest as it passes the clamp and then carries a moment that falls a little as the
  overhang curls, so the law's friction keeps it more bent than a monotonic loading would.

For an elastic strip the two give the same shape at every overhang (the law has no memory);
with the friction moment the pushed strip is bent more and meets the 41.5° line at a shorter
overhang. Peirce's bending length of each:

    python benchmarks/pushed_elastica.py                   # fabric1, warp
    python benchmarks/pushed_elastica.py --elastic
"""
from __future__ import annotations

import argparse
import dataclasses
import sys

import numpy as np

G0 = 9.80665


class Elastica:
    """Quasi-static strip of ``length`` [m] under ``weight`` [N/m²], in segments of about ``ds``.

    ``ds`` is rounded so that the segments fill ``length``. Segment ``k`` spans
    ``[k ds, (k + 1) ds]`` from the strip's held end; the clamp is at a segment boundary,
    ``clamp`` segments from that end. The law's state has one point per segment.
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

    def gravity_moment(self, kappa_free, factor):
        """Moment of the weight beyond each segment's mid-point, about it [N·m/m]."""
        ds = self.ds
        theta_mid, x_end, _ = self.shape(kappa_free)
        x_mid = x_end - 0.5 * ds * np.cos(theta_mid)
        # segments j > i as point loads at their mid-points; the outer half of segment i itself
        beyond_count = np.arange(len(x_mid))[::-1]
        sum_x_beyond = np.cumsum(x_mid[::-1])[::-1] - x_mid
        M = ds * (sum_x_beyond - beyond_count * x_mid) + 0.125 * ds * ds * np.cos(theta_mid)
        return factor * self.weight * M

    def solve(self, clamp: int, factor: float = 1.0, tol: float = 1e-12):
        """Equilibrium of the overhang beyond segment ``clamp`` under ``factor`` × the weight;
        commits the law's state and returns the overhang's curvatures."""
        free = slice(clamp, self.n)
        k = self.kappa[free].copy()
        trial_state = self.state
        for _ in range(100):
            kfull = self.kappa.copy()
            kfull[free] = k
            M, dM = trial_state.trial(kfull)
            r = M[free] - self.gravity_moment(k, factor)
            scale = max(float(np.abs(self.gravity_moment(k, factor)).max()), 1e-30)
            if np.abs(r).max() <= tol * scale:
                break
            J = np.diag(dM[free]) - self._gravity_jacobian(k, factor)
            step = np.linalg.solve(J, -r)
            lam = 1.0
            while lam > 1e-4:    # halve until the residual falls
                kt = k + lam * step
                kfull[free] = kt
                rt = trial_state.trial(kfull)[0][free] - self.gravity_moment(kt, factor)
                if np.abs(rt).max() < np.abs(r).max():
                    break
                lam *= 0.5
            k = kt
        else:
            raise RuntimeError(f"no equilibrium at clamp {clamp}, factor {factor}")
        self.kappa[:clamp] = 0.0
        self.kappa[free] = k
        self.state.commit(self.kappa)
        return k

    def _gravity_jacobian(self, k, factor, h=1e-7):
        """Forward differences of :meth:`gravity_moment` (dense; a few hundred segments)."""
        base = self.gravity_moment(k, factor)
        J = np.empty((len(k), len(k)))
        for j in range(len(k)):
            kp = k.copy()
            kp[j] += h
            J[:, j] = (self.gravity_moment(kp, factor) - base) / h
        return J

    def chord_angle(self, k) -> float:
        """Angle [deg] below the horizontal of the chord from the clamp to the tip."""
        _, x, z = self.shape(k)
        return float(np.degrees(np.arctan2(z[-1], x[-1])))


def clamped_chord(law, weight, overhang, ds, ramp_steps=20) -> float:
    """Chord angle [deg] of the strip clamped at ``overhang`` as its weight grows from nothing."""
    strip = Elastica(law, weight, overhang, ds)
    for f in np.linspace(0.0, 1.0, ramp_steps + 1)[1:]:
        k = strip.solve(0, f)
    return strip.chord_angle(k)


def pushed_overhang(law, weight, start, end, ds, line=41.5, ramp_steps=20) -> float:
    """Overhang [m] at which the strip pushed over the clamp from ``start`` meets ``line`` [deg]
    (linear between segments); NaN if not by ``end``."""
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


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--material", default="fabric1")
    parser.add_argument("--elastic", action="store_true", help="the law without its friction moment")
    parser.add_argument("--ds", type=float, default=1e-4, help="segment length [m] (default 0.1 mm)")
    parser.add_argument("--clamped", type=float, default=0.0163, help="the cantilever's overhang [m]")
    parser.add_argument("--start", type=float, default=0.0145, help="the pushed strip's first overhang [m]")
    parser.add_argument("--end", type=float, default=0.0175, help="the pushed strip's last overhang [m]")
    args = parser.parse_args(argv)
    from constitutive.material import load_material
    from drape.analyses.bending_length import bending_length

    material = load_material(args.material)
    law = material.warp
    if args.elastic:
        law = dataclasses.replace(law, friction=None)
    weight = material.areal_mass * G0
    angle = clamped_chord(law, weight, args.clamped, args.ds)
    c_clamped = bending_length(args.clamped, np.radians(angle))
    overhang = pushed_overhang(law, weight, args.start, args.end, args.ds)
    c_pushed = bending_length(overhang, np.radians(41.5))
    print(f"clamped at {100 * args.clamped:.2f} cm: chord angle {angle:.3f}°, c = {1000 * c_clamped:.3f} mm")
    print(f"pushed: meets 41.5° at {100 * overhang:.4f} cm, c = {1000 * c_pushed:.3f} mm")
    print(f"pushed / clamped bending length: {c_pushed / c_clamped:.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
