"""``report.html`` of an identification: measured and simulated drapes side by side.

Self-contained (inline CSS, PNGs as base64 data URIs, no scripts): the identified parameters
and their intervals; top views of the scans and of the identified point's simulated drapes;
their outlines ``r(θ)`` overlaid and their harmonic spectra (which do not depend on where the
folds sit); the misfit against the evaluations; in two dimensions the surrogate's misfit map.
"""
from __future__ import annotations

import base64
import html
from pathlib import Path

import numpy as np

from drape.analyses.drape_coefficient import plot_top_view
from drape.analyses.scan import ScanError
from drape.analyses.scan_measure import measure_scan
from drape.batch.report import figure_data_uri, new_figure
from drape.run.output import read_pvd

__all__ = ["simulated_measurements", "write_report"]

CSS = """body { font-family: sans-serif; margin: 2em; max-width: 70em; }
table { border-collapse: collapse; } td, th { border: 1px solid #ccc; padding: 0.3em 0.6em; }
th { background: #eef; } figure { display: inline-block; margin: 0.4em; }
figcaption { text-align: center; font-size: 0.85em; } img.top { width: 220px; }
.note { color: #555; font-size: 0.9em; }"""


def _uri_of_png(path: Path) -> str:
    return "data:image/png;base64," + base64.b64encode(Path(path).read_bytes()).decode("ascii")


def simulated_measurements(evaluation) -> list:
    """The identified point's simulated drapes read like scans (their last VTU, disc centre at
    the origin), for their outlines and top views."""
    out = []
    for run in evaluation.runs:
        drape = run.get("drape")
        if not drape or not drape.get("pvd"):
            continue
        listed = read_pvd(Path(run["run_dir"]) / drape["pvd"])
        try:
            out.append(measure_scan(listed[-1][1], centre=(0.0, 0.0), name=drape["name"]))
        except (ScanError, IndexError):
            continue
    return out


def _top_views(measurements, folder: Path) -> str:
    folder.mkdir(parents=True, exist_ok=True)
    cells = []
    for m in measurements:
        png = plot_top_view(m.result, folder / f"{m.name}_top.png", title=m.name)
        s = m.result.summary()
        cells.append(f'<figure><img class="top" src="{_uri_of_png(png)}"><figcaption>'
                     f'{html.escape(m.name)}: DC {s["drape_coefficient_percent"]:.1f} %, '
                     f'{s["n_nodes"]} nodes</figcaption></figure>')
    return "".join(cells)


def _outlines(scans, simulated) -> str:
    fig = new_figure((10, 3.6))
    ax, bx = fig.subplots(1, 2)
    for group, colour, label in ((scans, "C0", "scan"), (simulated, "C3", "simulated")):
        for i, m in enumerate(group):
            ax.plot(np.degrees(m.result.angles), 1e2 * m.result.radius, color=colour, lw=1,
                    alpha=0.7, label=label if i == 0 else None)
        if group:
            a = 1e3 * np.array([m.result.summary()["outline_harmonics_m"] for m in group])
            k = np.arange(a.shape[1])
            shift = -0.2 if colour == "C0" else 0.2
            bx.bar(k[1:] + shift, a.mean(axis=0)[1:], width=0.4, color=colour, label=label,
                   yerr=a.std(axis=0)[1:] if len(group) > 1 else None)
    ax.set(xlabel="θ (deg)", ylabel="outline radius r(θ) (cm)", title="outlines")
    bx.set(xlabel="harmonic k", ylabel="amplitude a_k (mm)", title="spectra (mean ± sd)")
    ax.legend(), bx.legend()
    return f'<img src="{figure_data_uri(fig, dpi=90)}">'


def _objective(history) -> str:
    fig = new_figure((5.5, 3.4))
    ax = fig.subplots()
    J = np.array([h["J"] for h in history])
    ax.semilogy(np.arange(1, len(J) + 1), 1 + J, "o", ms=4, label="evaluation")
    ax.semilogy(np.arange(1, len(J) + 1), 1 + np.minimum.accumulate(J), "-", label="best so far")
    ax.axhline(2.0, color="0.5", ls=":", label="J = 1 (within the scans' scatter)")
    ax.set(xlabel="evaluation (library first)", ylabel="1 + J", title="misfit")
    ax.legend(fontsize=8)
    return f'<img src="{figure_data_uri(fig, dpi=90)}">'


def _surrogate_map(surrogate, history, answer) -> str:
    if surrogate is None or len(surrogate.names) != 2:
        return ""
    x, y = surrogate.names
    points = surrogate.sample()
    J, _ = surrogate.predict(points)
    side = int(round(np.sqrt(len(points))))
    X = np.array([p[x] for p in points]).reshape(side, side)
    Y = np.array([p[y] for p in points]).reshape(side, side)
    fig = new_figure((5.5, 4.2))
    ax = fig.subplots()
    c = ax.contourf(X, Y, np.log10(1 + J.reshape(side, side)), levels=20, cmap="viridis_r")
    fig.colorbar(c, ax=ax, label="log10(1 + J), surrogate mean")
    ax.contour(X, Y, J.reshape(side, side), levels=[answer["J_surrogate"] + 1.0], colors="w")
    ax.plot([h["point"][x] for h in history], [h["point"][y] for h in history], "k.", ms=5)
    ax.plot(answer["point"][x], answer["point"][y], "r*", ms=12)
    ax.set(xscale="log", yscale="log", xlabel=x, ylabel=y,
           title="surrogate misfit (white: within 1 of the minimum)")
    return f'<img src="{figure_data_uri(fig, dpi=90)}">'


def _table(result: dict) -> str:
    rows = []
    for k, v in result["parameters"].items():
        iv = result["intervals"][k]
        edge = f" (box edge: {', '.join(iv['at_box_edge'])})" if iv["at_box_edge"] else ""
        rows.append(f"<tr><td>{k}</td><td>{v:.4g}</td><td>{iv['low']:.4g} – {iv['high']:.4g}"
                    f"{edge}</td><td>{html.escape(result['units'][k])}</td></tr>")
    return ("<table><tr><th>parameter</th><th>identified</th><th>interval</th><th>unit</th></tr>"
            + "".join(rows) + "</table>")


def write_report(out: Path, result: dict, scans, simulated, history, surrogate=None) -> Path:
    """Write ``out/report.html``; return its path."""
    out = Path(out)
    t, s = result["target"], result["simulated"]
    kes = ", ".join(f"{k} {v:.4g}" for k, v in result["material_kes"].items())
    body = [
        "<h1>Identification from Cusick drapes</h1>",
        f"<p>{t['drapes']} scans: DC {t['DC_mean_percent']:.1f} ± {t['DC_std_percent']:.1f} %, "
        f"nodes {t['nodes_histogram']}. Identified point ({s['drapes']} seeds): DC "
        f"{s['DC_mean_percent']:.1f} ± {s['DC_std_percent']:.1f} %, nodes {s['nodes_histogram']}."
        f" Misfit J = {result['misfit']['J']:.2f} (z_DC {result['misfit']['z_DC']:.2f}, z_nodes "
        f"{result['misfit']['z_nodes']:.2f}, spectrum {result['misfit']['spectrum']:.2f}).</p>",
        "" if result["matched"] else
        "<p><b>Not matched:</b> the identified point's DC is over two standard deviations of "
        "the scans' scatter off theirs; the parameters below are the nearest the model came.</p>",
        _table(result),
        f"<p>Material file <code>{html.escape(result['material_file'])}</code> (at W = "
        f"{result['weight_mg_per_cm2']:g} mg/cm²): {kes}.</p>",
        f"<p class='note'>{html.escape(result['interval_rule'])}</p>",
        "<h2>Top views</h2><h3>scans</h3>", _top_views(scans, out / "pictures"),
        "<h3>simulated at the identified point</h3>", _top_views(simulated, out / "pictures"),
        "<h2>Outlines r(θ) and spectra</h2>", _outlines(scans, simulated),
        "<h2>Misfit against evaluations</h2>", _objective(history),
        _surrogate_map(surrogate, history, result["surrogate"]),
        "<h2>Where the time went</h2><table>" + "".join(
            f"<tr><td>{k}</td><td>{v:.1f} s</td></tr>" for k, v in result["seconds"].items())
        + "</table>",
    ]
    page = (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>identification</title>"
            f"<style>{CSS}</style></head><body>{''.join(body)}</body></html>")
    path = out / "report.html"
    path.write_text(page)
    return path
