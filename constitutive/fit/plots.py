"""Plots of a fitted KES-FB loop, like the thesis's Figs 4.8–4.34 (PNG).

Three panels in KES units: (a) measured data (thesis polynomial or CSV points)
and the model loop, (b) the friction contribution ``M_f`` (Figs 4.13, 4.19,
4.27, 4.33), (c) the visco-elastic contribution
``m κ̈ + d κ̇ + k1 κ + k3 κ³`` (Figs 4.14, 4.20, 4.28, 4.34).

>>> import tempfile, os
>>> from constitutive.fit import fit
>>> r = fit("fabric2-weft", "linear")
>>> with tempfile.TemporaryDirectory() as d:
...     out = plot_fit(r, os.path.join(d, "loop.png"))
...     os.path.getsize(out) > 10_000
True
"""

from __future__ import annotations

from constitutive.datasets import CURVATURE_KES, MOMENT_KES

__all__ = ["plot_fit"]


def plot_fit(result, path, points=None, dpi=120):
    """Write the 3-panel figure of a :class:`constitutive.fit.FitResult` to ``path``.

    Parameters
    ----------
    result : FitResult
    path : str or Path
        PNG file to write.
    points : tuple of ndarray, optional
        Raw measured (kappa, moment) in SI to show as dots (CSV data).
    dpi : int

    Returns
    -------
    path
    """
    # matplotlib only when a plot is asked for; drawn without pyplot: the caller's backend is left alone
    from matplotlib.figure import Figure

    loop = result.loop
    k = loop.kappa / CURVATURE_KES
    M = result.model / MOMENT_KES
    Mf = result.friction_moment / MOMENT_KES
    data = loop.moment / MOMENT_KES
    fig = Figure(figsize=(15, 4.6), constrained_layout=True)
    axes = fig.subplots(1, 3)
    ax = axes[0]
    if points is not None:
        ax.plot(points[0] / CURVATURE_KES, points[1] / MOMENT_KES, ".", ms=2, color="0.6",
                label="measured points")
    ax.plot(k, data, ":", color="k", lw=1.5, label="data on machine profile")
    ax.plot(k, M, "-", color="C3", lw=1.2, label="model")
    ax.set_title(f"{result.dataset} — {result.variant} (R = {result.residual:.3e})")
    ax.legend(loc="upper left", fontsize=8)
    axes[1].plot(k, Mf, "-", color="C0")
    axes[1].set_title("friction contribution $M_f$")
    axes[2].plot(k, M - Mf, "-", color="C2")
    axes[2].set_title(r"visco-elastic contribution $m\ddot\kappa + d\dot\kappa + k_1\kappa + k_3\kappa^3$")
    for a in axes:
        a.set_xlabel("curvature κ [cm⁻¹]")
        a.set_ylabel("moment [gf·cm/cm]")
        a.axhline(0, color="0.8", lw=0.5)
        a.axvline(0, color="0.8", lw=0.5)
        a.grid(alpha=0.3)
    fig.savefig(path, dpi=dpi)
    return path
