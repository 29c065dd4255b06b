"""The ``[load]`` tables of a case file: the loads of :mod:`drape.models.loads` as case keys.

Each load (self-weight, pressure, follower end moment) is a constant times an amplitude
``a(t)``: a smooth ramp to 1, or a table of ``(t, a)`` points blended by C¹ cubics
(:func:`amplitude`). Shaking the supports (:class:`Agitation`) adds to the self-weight factor.
The KES-FB drive imposes the curvature profile of :func:`constitutive.kes.kes_profile`
(:func:`kes_curvature`).
"""
from __future__ import annotations

from typing import Annotated, Callable, Literal

import numpy as np
from pydantic import Field, field_validator, model_validator

from constitutive.kes import kes_profile
from constitutive.units import G0
from drape.case.quantities import Q, _rule, _Section
from drape.models.loads import amplitude

__all__ = ["Amplitude", "Gravity", "Pressure", "EndMoment", "KesDrive",
           "Perturbation", "Agitation", "LoadSpec", "load_amplitudes", "kes_curvature"]


def _check_history(history):
    if history is None:
        return history
    times = [row[0] for row in history]
    if any(b <= a for a, b in zip(times, times[1:])):
        raise ValueError("history times must increase strictly")
    return history


History = Annotated[
    list[Annotated[list[float], Field(min_length=2, max_length=2)]] | None,
    Field(min_length=2),
]


class Amplitude(_Section):
    """A load amplitude in time: ``factor`` reached over a smooth ``ramp_time``, or a ``history``."""

    ramp_time: Q("s", ge=0) = 0.0
    """Duration of the smooth (C¹, cubic) ramp from 0 to full load [s]; 0 = applied at once."""
    history: History = None
    """Amplitude table ``[[t0, f0], [t1, f1], ...]`` (times in s); replaces the ramp.
    Outside the table the end values hold."""
    smooth: bool = True
    """Blend each history segment with the C¹ cubic of ``ramp_time`` (zero load rate at every
    table point, no jerk into the dynamics); ``false``: piecewise linear."""

    _check = field_validator("history")(classmethod(lambda cls, v: _check_history(v)))

    @model_validator(mode="after")
    def _ramp_or_history(self):
        if self.history is not None and "ramp_time" in self.model_fields_set:
            raise _rule("@: give ramp_time or history, not both")
        return self

    def amplitude(self, t: float) -> float:
        """Load factor at time ``t`` (multiplies ``factor``/``value``; :func:`amplitude`).

        >>> Amplitude(ramp_time=1.0).amplitude(0.5)
        0.5
        """
        return amplitude(t, self.ramp_time, self.history, self.smooth)

    def end_time(self) -> float:
        """Time after which the amplitude no longer changes."""
        return self.history[-1][0] if self.history is not None else self.ramp_time


class Gravity(Amplitude):
    """[load.gravity]: self-weight −ρ_A g e_z (g = 9.80665 m/s²) times factor × amplitude(t).

    A gravity cycle (load, unload, reverse) is a ``history`` such as
    ``[[0, 0], [1, 1], [2, 1], [3, 0], [4, -1], [5, -1], [6, 0]]``.
    """

    factor: float = 1.0
    """Multiplier of the self-weight (negative turns the fabric upside down)."""


class Pressure(Amplitude):
    """[load.pressure]: uniform pressure along +z [N/m²] times amplitude(t)."""

    value: Q("N/m**2")
    """Pressure along +z [N/m²]."""


class EndMoment(Amplitude):
    """[load.end_moment]: follower moment per unit width on a boundary [N·m/m = N]."""

    value: Q("N")
    """Moment per unit width [N]; positive curls the fabric face-up (towards +z)."""
    boundary: str = "free_end"
    """Boundary carrying the moment."""


class KesDrive(_Section):
    """[load.kes]: drive a strip through the KES-FB pure-bending profile by imposed end rotation.

    Both ends are held in clamps rotated by ±κ(t) L / 2, which bends an unloaded uniform strip
    to the uniform curvature κ(t) of the KES profile 0 → K+ → K− → 0
    (``drape.models.plate.pure_bending_rotations``; small kinematics).
    """

    ends: list[str] = Field(["left", "right"], min_length=2, max_length=2)
    """The two strip ends (mesh boundary names) held in the rotating clamps."""
    k_max: Q("1/m", gt=0) = 250.0
    """Turning curvature K+ [1/m] (KES-FB: 2.5 cm⁻¹)."""
    k_min: Q("1/m", lt=0) | None = None
    """Turning curvature K− [1/m]; default −k_max."""
    rate: Q("1/m/s", gt=0) = 50.0
    """Curvature rate v [1/m/s] (KES-FB: 0.5 cm⁻¹/s)."""
    accel_time: Q("s", gt=0) = 0.5
    """Acceleration/deceleration time T at each turning point [s] (equipment constant)."""

    def profile_kwargs(self) -> dict:
        """Keyword arguments of ``constitutive.kes.kes_profile``."""
        return dict(rate=self.rate, accel_time=self.accel_time, k_max=self.k_max,
                    k_min=-self.k_max if self.k_min is None else self.k_min)

    def duration(self) -> float:
        """Length of the test 0 → K+ → K− → 0 [s] (the end of ``kes_profile``'s last phase).

        >>> KesDrive().duration()
        21.5
        """
        return float(kes_profile(t=[0.0], **self.profile_kwargs()).phase_times[-1])


class Perturbation(_Section):
    """[load.perturbation]: seeded out-of-plane imperfection so that a symmetric drape can buckle
    into folds (``drape.models.perturbation``). On a Cusick specimen ``w = A s(ρ) g(φ)`` with
    s = ((ρ − r_disc)/(R − r_disc))², zero with its slope at the disc; on a strip or rectangle
    ``w = A ξ² g(ξ)``, ξ = x / length, zero with its slope at the left end, g a sum of cos(k π ξ + φ_k)
    (k half-waves over the length)."""

    kind: Literal["none", "lobed", "random"] = "random"
    """``lobed``: one mode cos(n φ + φ0) (imposes n folds; on a strip n half-waves); ``random``:
    modes k_min..k_max with seeded amplitudes and phases (the fabric picks its node count)."""
    amplitude: float = Field(1e-3, ge=0)
    """A: fraction of the weight (target force), metres (displacement) or m/s (velocity)."""
    seed: int = 0
    """Random seed of the phases/amplitudes (same seed, same field)."""
    n_lobes: int = Field(6, ge=1)
    """Mode number for kind = "lobed"."""
    k_min: int = Field(2, ge=1)
    """Lowest mode for kind = "random"."""
    k_max: int = Field(12, ge=1)
    """Highest mode for kind = "random"."""
    target: Literal["force", "displacement", "velocity"] = "displacement"
    """``force``: transient load A ρ_A g s g(φ) sin²(π t / duration) on [0, duration] (starts at
    rest, same on every mesh; recommended); ``displacement``/``velocity``: initial u_z/v_z."""
    duration: Q("s", gt=0) = 0.2
    """Length of the transient load of target = "force"."""

    @model_validator(mode="after")
    def _modes(self):
        if self.k_min > self.k_max:
            raise _rule(f"@.k_min = {self.k_min} must not exceed @.k_max = {self.k_max}")
        return self


class Agitation(_Section):
    """[load.agitation]: the supports shaken up and down, as a drape tester's disc is tapped or
    vibrated before the drape is read, to free the folds that friction holds.

    The supports' vertical acceleration is a sine burst under a Hann window,
    ``a(t) = A g sin(2π f τ) sin²(π τ / T)``, ``τ = t − start`` in ``[0, T]``, ``T = cycles / f``:
    it starts and ends with zero acceleration, jerk and (whole cycles) velocity, so the supports
    come back to rest. The run is computed in the frame of the supports, where their motion is
    exactly a change of the weight: ``g → g + a(t)``, plus the air drag ``α ρ_A v(t)`` of the
    frame's velocity ``v`` (mass damping α; :func:`load_amplitudes`). Displacements stay relative
    to the supports.
    """

    acceleration: float = Field(gt=0, le=2)
    """Peak vertical acceleration of the supports, as a fraction of g."""
    frequency: Q("Hz", gt=0) = 2.0
    """Shaking frequency [Hz]. 2 Hz is near the swing frequency of a 6 cm skirt
    (√(g/L)/2π), where a shake moves the skirt most."""
    cycles: int = Field(3, ge=2)
    """Number of whole cycles of the burst (at least 2: then the velocity returns to zero)."""
    start: Q("s", ge=0) | None = None
    """Time the burst begins [s]; default: when the other loads stop changing (after the
    gravity ramp and the perturbation; [load] fills it in)."""

    def window(self) -> tuple[float, float]:
        """``(start, end)`` of the burst [s].

        >>> Agitation(acceleration=0.3, frequency=2.0, cycles=3, start=2.0).window()
        (2.0, 3.5)
        """
        t0 = self.start or 0.0
        return t0, t0 + self.cycles / self.frequency

    def support_motion(self, t: float) -> tuple[float, float]:
        """Vertical ``(acceleration [m/s²], velocity [m/s])`` of the supports at time ``t``.

        The velocity is the exact integral of the acceleration from the burst's start.

        >>> shake = Agitation(acceleration=0.5, frequency=1.0, cycles=2, start=0.0)
        >>> a, v = shake.support_motion(0.75)
        >>> round(a / 9.80665, 4), round(v, 4)
        (-0.4268, -0.314)
        >>> abs(shake.support_motion(2.0 - 1e-9)[1]) < 1e-12
        True
        """
        t0, t1 = self.window()
        if not t0 < t < t1:
            return 0.0, 0.0
        tau, amp = t - t0, self.acceleration * G0
        w, W = 2.0 * np.pi * self.frequency, 2.0 * np.pi / (t1 - t0)
        accel = amp * np.sin(w * tau) * np.sin(0.5 * W * tau) ** 2
        # ∫ sin(wτ) sin²(Wτ/2) = ∫ sin(wτ)/2 − [sin((w+W)τ) + sin((w−W)τ)]/4, W < w
        velocity = amp * ((1 - np.cos(w * tau)) / (2 * w)
                          - ((1 - np.cos((w + W) * tau)) / (w + W)
                             + (1 - np.cos((w - W) * tau)) / (w - W)) / 4)
        return float(accel), float(velocity)

    def stroke(self) -> float:
        """Peak-to-peak vertical travel of the supports during the burst [m].

        >>> round(1e3 * Agitation(acceleration=0.3, frequency=2.0, cycles=3).stroke(), 1)
        37.7
        """
        t = np.linspace(*self.window(), 512 * self.cycles + 1)
        v = np.array([self.support_motion(ti)[1] for ti in t])
        z = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
        return float(z.max() - z.min())

    def describe(self) -> dict:
        """The burst in SI units for summary.json: window, peak acceleration, stroke."""
        t0, t1 = self.window()
        return {"start_s": t0, "end_s": t1, "frequency_Hz": self.frequency, "cycles": self.cycles,
                "peak_acceleration_g": self.acceleration, "stroke_m": self.stroke()}


class LoadSpec(_Section):
    """[load]: external actions (any combination)."""

    gravity: Gravity | None = None
    """Self-weight, see [load.gravity]."""
    pressure: Pressure | None = None
    """Uniform pressure, see [load.pressure]."""
    end_moment: EndMoment | None = None
    """Follower end moment, see [load.end_moment]."""
    kes: KesDrive | None = None
    """KES-FB imposed-rotation drive, see [load.kes]."""
    perturbation: Perturbation | None = None
    """Initial fold imperfection of a Cusick specimen, see [load.perturbation]."""
    agitation: Agitation | None = None
    """The supports shaken before the reading, see [load.agitation]."""

    @model_validator(mode="after")
    def _shake_once_placed(self):
        if self.agitation is not None and self.agitation.start is None:
            self.agitation.start = self.end_time(agitation=False)
        return self

    def end_time(self, agitation: bool = True) -> float:
        """Time after which no load changes any more (0 if unloaded); ``agitation=False``:
        no load but the agitation."""
        if agitation and self.agitation is not None:
            return max(self.end_time(agitation=False), self.agitation.window()[1])
        parts = [self.gravity, self.pressure, self.end_moment]
        ends = [p.end_time() for p in parts if p is not None]
        if self.kes is not None:
            ends.append(self.kes.duration())
        if self.perturbation is not None and self.perturbation.target == "force":
            ends.append(self.perturbation.duration)
        return max(ends, default=0.0)


def load_amplitudes(case, mass_damping: float = 0.0) -> dict[str, Callable[[float], float]]:
    """Time functions of the loads: ``gravity`` (factor), ``pressure`` [Pa], ``end_moment`` [N].

    Shaken supports (``[load.agitation]``) add ``(a + α v) / g`` to the gravity factor: in their
    frame the inertia of their acceleration ``a`` and the drag ``α ρ_A v`` of their velocity
    (``mass_damping`` α [1/s], acting on absolute velocities) are weights.
    """
    load = case.load
    out: dict[str, Callable[[float], float]] = {}
    weight = None
    if load.gravity is not None:
        g = load.gravity
        weight = lambda t, g=g: g.factor * g.amplitude(t)  # noqa: E731
    if load.agitation is not None:
        shake, own = load.agitation, weight or (lambda t: 0.0)

        def weight(t: float) -> float:
            a, v = shake.support_motion(t)
            return own(t) + (a + mass_damping * v) / G0
    if weight is not None:
        out["gravity"] = weight
    if load.pressure is not None:
        p = load.pressure
        out["pressure"] = lambda t, p=p: p.value * p.amplitude(t)
    if load.end_moment is not None:
        m = load.end_moment
        out["end_moment"] = lambda t, m=m: m.value * m.amplitude(t)
    return out


def kes_curvature(case) -> Callable[[float], tuple[float, float, float]]:
    """``t -> (κ, κ̇, κ̈)`` of the KES-FB profile of ``[load.kes]`` (constitutive.kes.kes_profile).

    The exact rates let the plate lift the imposed motion exactly, so the law's d κ̇ and m κ̈
    see the profile's rates, not Newmark's estimates of them. After the profile's last phase
    the strip is held at its final curvature, at rest.
    """
    kwargs = case.load.kes.profile_kwargs()
    t_end = float(kes_profile(t=[0.0], **kwargs).phase_times[-1])

    def kappa(t: float) -> tuple[float, float, float]:
        if t >= t_end:
            p = kes_profile(t=[t_end], **kwargs)
            return float(p.kappa[0]), 0.0, 0.0
        p = kes_profile(t=[max(t, 0.0)], **kwargs)
        return float(p.kappa[0]), float(p.kappa_dot[0]), float(p.kappa_ddot[0])

    return kappa
