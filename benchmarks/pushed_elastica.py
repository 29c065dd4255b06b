"""The Peirce strip as an inextensible elastica with the bending law: clamped, or pushed over a clamp.

A reference for the platform Peirce case that shares nothing with the shell but the law
(:mod:`constitutive.elastica`): the strip is a row of material segments of length ``ds`` with
one curvature each; the part beyond the clamp hangs under its weight, quasi-statically (no
inertia, no viscosity), and each segment's moment is the law's (its friction remembers the
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
    python benchmarks/pushed_elastica.py --grip 3e10 --ds 2.5e-5

``--grip K`` also pushes the strip through a grip that gives: held at its rear end and lying up
to the edge on a two-sided elastic foundation of stiffness K [N/m³] (the platform case's
geometry, 2.2 cm of strip), as contact holds it by a couple instead of a moment.
"""
from __future__ import annotations

import argparse
import dataclasses
import sys

import numpy as np

from constitutive.elastica import clamped_chord, gripped_overhang, pushed_overhang
from constitutive.units import G0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--material", default="fabric1")
    parser.add_argument("--elastic", action="store_true", help="the law without its friction moment")
    parser.add_argument("--ds", type=float, default=1e-4, help="segment length [m] (default 0.1 mm)")
    parser.add_argument("--clamped", type=float, default=0.0163, help="the cantilever's overhang [m]")
    parser.add_argument("--start", type=float, default=0.0145, help="the pushed strip's first overhang [m]")
    parser.add_argument("--end", type=float, default=0.0175, help="the pushed strip's last overhang [m]")
    parser.add_argument("--grip", type=float, metavar="K",
                        help="also push through a grip of foundation stiffness K [N/m³]")
    parser.add_argument("--grip-every", type=int, default=1, metavar="N",
                        help="the grip at points N segments apart (contact points; default 1: everywhere)")
    parser.add_argument("--length", type=float, default=0.022, help="the gripped strip's length [m]")
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
    if args.grip:
        gripped = gripped_overhang(law, weight, args.length, args.start, args.end, args.ds, args.grip,
                                   every=args.grip_every)
        print(f"pushed through the grip (K = {args.grip:g} N/m³): meets 41.5° at {100 * gripped:.4f} cm, "
              f"{gripped / overhang:.4f} of the perfect clamp's overhang")
    return 0


if __name__ == "__main__":
    sys.exit(main())
