"""Loads as plain functions of time, as the models take them.

A model's load (self-weight factor, pressure, end moment, edge load) is a number, an array or
a callable ``t -> value`` (:func:`as_function`); the case file's ``[load]`` tables
(:mod:`drape.case.loads`) build their amplitudes with :func:`amplitude`.
"""
from __future__ import annotations

import numpy as np

__all__ = ["as_function", "amplitude"]


def as_function(value, name: str, error: type[Exception] = ValueError):
    """A load given as a number, an array, a bool or a callable of time, as a callable of time.

    None stays None (no such load); a bool is 1 or 0. ``error`` is the exception raised for a
    value that is none of these, naming ``name``.

    >>> as_function(2, "gravity")(0.5), as_function(True, "gravity")(0.0)
    (2.0, 1.0)
    >>> as_function("heavy", "gravity")
    Traceback (most recent call last):
    ...
    ValueError: gravity must be a number, an array or a callable t -> value, got 'heavy'
    """
    if value is None or callable(value):
        return value
    if isinstance(value, (bool, np.bool_)):
        value = 1.0 if value else 0.0
    try:
        const = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise error(f"{name} must be a number, an array or a callable t -> value, got {value!r}") from None
    if not np.all(np.isfinite(const)):
        raise error(f"{name} must be finite, got {value!r}")
    const = float(const) if const.ndim == 0 else const
    return lambda t: const


def amplitude(t: float, ramp_time: float = 0.0, history=None, smooth: bool = True) -> float:
    """Load amplitude at time ``t``: a C¹ cubic ramp ``s² (3 − 2 s)`` over ``ramp_time``, or the
    ``history`` table ``[[t0, a0], [t1, a1], ...]`` (each segment blended by the same cubic
    when ``smooth``, else linear; the end values hold outside the table).

    >>> amplitude(0.5, ramp_time=1.0), amplitude(0.0)
    (0.5, 1.0)
    >>> amplitude(1.5, history=[[0, 0], [1, 1], [2, -1]])
    0.0
    >>> amplitude(0.25, history=[[0, 0], [1, 1]], smooth=False)
    0.25
    >>> amplitude(0.25, history=[[0, 0], [1, 1]])
    0.15625
    """
    if history is not None:
        ts, fs = (np.array(c, dtype=float) for c in zip(*history))
        if not smooth or t <= ts[0] or t >= ts[-1]:
            return float(np.interp(t, ts, fs))
        i = int(np.searchsorted(ts, t, side="right")) - 1
        s = (t - ts[i]) / (ts[i + 1] - ts[i])
        return float(fs[i] + (fs[i + 1] - fs[i]) * s * s * (3.0 - 2.0 * s))
    if ramp_time <= 0:
        return 1.0
    s = min(max(t / ramp_time, 0.0), 1.0)
    return s * s * (3.0 - 2.0 * s)
