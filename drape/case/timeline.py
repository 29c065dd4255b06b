"""The times a run steps through: phases of the time step, and times it must land on.

A dynamic run steps with ``solver.dt`` while the loads change and, when ``solver.settling_dt``
is given, lets the step grow once they are constant (:func:`time_phases`). Output marks,
corners of load histories and the KES-FB turning points are landed on exactly
(:func:`hit_times`); a quasi-static run steps through the pseudo-times :func:`pseudo_times`.
"""
from __future__ import annotations

import math

import numpy as np

from constitutive.kes import kes_profile

__all__ = ["time_phases", "hit_times", "pseudo_times", "changes_end"]


def changes_end(case) -> float:
    """Time after which nothing the run is driven by changes: the loads
    (:meth:`drape.case.loads.LoadSpec.end_time`) and the contact bodies' paths (their last
    keyframe); the settling phase and the ``[stop]`` rule start there.

    >>> from drape.case.case import parse_case
    >>> c = parse_case({"case": {"name": "x"}, "material": {"name": "f"},
    ...     "mesh": {"kind": "strip", "length": 1.0, "width": 0.1, "nx": 4},
    ...     "model": {"kinematics": "large"}, "load": {"gravity": {"ramp_time": 0.2}},
    ...     "contact": {"thickness": 1e-3, "body": [{"name": "floor", "shape": "plane",
    ...         "point": [0, 0, -0.01], "size": 2.0,
    ...         "path": {"times": [0.5, 1.5], "translations": [[0, 0, 0], [0, 0, -0.1]]}}]},
    ...     "solver": {"dt": 0.01, "t_end": 3.0}})
    >>> changes_end(c)
    1.5
    """
    ends = [case.load.end_time()]
    contact = getattr(case, "contact", None)
    for body in (contact.body if contact is not None else ()):
        if body.path is not None:
            ends.append(float(body.path.times[-1]))
    return max(ends)


def time_phases(case) -> list[tuple[float, float, bool]]:
    """``(t_stop, dt_max, settling)`` of each stretch of a dynamic run: ``dt`` while loads
    change or a contact body moves, then (when ``settling_dt`` is given, once nothing changes,
    :func:`changes_end`) a settling phase whose step grows from ``dt`` up to ``settling_dt``.

    >>> from drape.case.case import parse_case
    >>> c = parse_case({"case": {"name": "x"}, "material": {"name": "f"},
    ...     "mesh": {"kind": "strip", "length": 1.0, "width": 0.1, "nx": 4},
    ...     "load": {"gravity": {"ramp_time": 0.2}},
    ...     "solver": {"dt": 0.01, "t_end": 1.0, "settling_dt": 0.05}})
    >>> time_phases(c)
    [(0.2, 0.01, False), (1.0, 0.05, True)]
    """
    solver = case.solver
    t_change = changes_end(case)
    if solver.settling_dt is None or t_change >= solver.t_end:
        return [(solver.t_end, solver.dt, False)]
    settle = (solver.t_end, solver.settling_dt, True)
    return [settle] if t_change <= 0.0 else [(t_change, solver.dt, False), settle]


def hit_times(case) -> list[float]:
    """Times the integrator must land on: output marks, load-history corners, KES turning points.

    >>> from drape.case.case import parse_case
    >>> c = parse_case({"case": {"name": "x"}, "material": {"name": "f"},
    ...     "mesh": {"kind": "strip", "length": 1.0, "width": 0.1, "nx": 4},
    ...     "load": {"gravity": {"history": [[0, 0], [0.35, 1]]}},
    ...     "output": {"every_dt": 0.25}, "solver": {"dt": 0.1, "t_end": 0.6}})
    >>> hit_times(c)
    [0.25, 0.35, 0.5]
    """
    t_end = case.solver.t_end
    times: set[float] = set()
    if case.output.every_dt is not None:
        n = int(math.floor(t_end / case.output.every_dt + 1e-9))
        times.update(k * case.output.every_dt for k in range(1, n + 1))
    load = case.load
    for part in (load.gravity, load.pressure, load.end_moment):
        if part is None:
            continue
        if part.history is not None:
            times.update(row[0] for row in part.history)
        elif part.ramp_time > 0:
            times.add(part.ramp_time)
    if load.kes is not None:
        times.update(kes_profile(**load.kes.profile_kwargs()).phase_times.tolist())
    contact = getattr(case, "contact", None)
    for body in (contact.body if contact is not None else ()):
        if body.path is not None:           # a body's path turns a corner at its keyframes
            times.update(float(t) for t in body.path.times)
    return sorted(t for t in times if 0.0 < t < t_end)


def pseudo_times(dt: float, t_end: float) -> np.ndarray:
    """Equal pseudo-time steps of at most ``dt`` up to ``t_end`` (quasi-static runs).

    >>> pseudo_times(0.4, 1.0)
    array([0.33333333, 0.66666667, 1.        ])
    """
    n = max(1, int(math.ceil(t_end / dt - 1e-9)))
    return np.linspace(t_end / n, t_end, n)
