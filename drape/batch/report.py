"""A report to open in a browser: :func:`write_report` writes ``OUTDIR/report.html``
(``python -m drape.report OUTDIR``, :mod:`drape.cli.report`).

For a sweep folder (``results.csv`` from :mod:`drape.batch.sweep`) the report has the results
table, the drape coefficient against the bending length c = (B/W)^(1/3) (with the measured
values when the run table had a ``measured.DC`` column), a top view of every run and links
to the PVD files, and the seed ensembles when there are any (``ensemble.json`` of
``--seeds``: DC and nodes as mean ± standard deviation, the node-count histogram and how
many seeds agreed). For a single run folder (``summary.json`` from :mod:`drape.run.runner`) it has
the summary, the history of the energies and a top view.

The page is self-contained: inline CSS, pictures as base64 PNG data URIs, no scripts and no
remote resources, so it opens on a machine without network. Links to the PVD files and run
folders are relative, so the folder can be moved or zipped as a whole.
"""
from __future__ import annotations

import base64
import csv
import html
import io
import json
import math
from pathlib import Path

import numpy as np

from drape.batch.rows import RESULT_COLUMNS, read_results
from drape.run.atomic import atomic_write_text
from drape.run.output import read_pvd

__all__ = ["figure_data_uri", "new_figure", "top_view_figure", "draw_top_view", "dc_figure", "history_figure", "sweep_report", "run_report",
           "write_report"]

_CSS = """
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.4em; } h2 { font-size: 1.15em; margin-top: 1.5em; }
table { border-collapse: collapse; font-size: 0.85em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.5em; text-align: right; vertical-align: middle; }
th { background: #eef; } td.text { text-align: left; }
tr.bad td { background: #fee; }
img.thumb { width: 140px; height: 140px; }
figure { display: inline-block; margin: 0.5em; } figcaption { text-align: center; font-size: 0.85em; }
.note { color: #666; font-size: 0.9em; }
"""

#: Statuses of a run that ended as it should.
GOOD = ("completed", "settled")


# --------------------------------------------------------------------------- pictures
def figure_data_uri(fig, dpi: int = 80) -> str:
    """A matplotlib figure as a PNG ``data:`` URI, for a self-contained HTML page."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def new_figure(size):
    """A matplotlib figure off pyplot (no global state, no display), laid out constrained."""
    from matplotlib.figure import Figure

    return Figure(figsize=size, layout="constrained")


def _last_vtu(run_dir: Path, pvd: str | None = None) -> Path | None:
    pvds = [run_dir / pvd] if pvd else sorted(run_dir.glob("*.pvd"))
    for path in pvds:
        if path.exists():
            listed = read_pvd(path)
            if listed:
                return listed[-1][1]
    return None


def top_view_figure(vtu_path, size: float = 2.4):
    """Top view of the deformed fabric of one VTU step: triangles at their deformed (x, y),
    coloured by height z; the undeformed outline dashed.

    Returns a matplotlib ``Figure`` (not attached to pyplot).
    """
    fig = new_figure((size, size))
    draw_top_view(fig.add_subplot(), vtu_path)
    return fig


def draw_top_view(ax, vtu_path) -> None:
    """Draw :func:`top_view_figure`'s picture on the matplotlib axes ``ax`` (in cm)."""
    import meshio
    from matplotlib.collections import LineCollection
    from matplotlib.tri import Triangulation

    mesh = meshio.read(vtu_path)
    tri = mesh.cells_dict["triangle"]
    x0 = np.asarray(mesh.points, dtype=float)
    u = np.asarray(mesh.point_data.get("displacement", np.zeros_like(x0)), dtype=float)
    x = x0 + np.pad(u, ((0, 0), (0, 3 - u.shape[1])))
    scale = 100.0   # cm, as a drape meter's scale reads
    deformed = Triangulation(scale * x[:, 0], scale * x[:, 1], tri)
    ax.tripcolor(deformed, scale * x[:, 2], shading="gouraud", cmap="viridis")
    # the flat specimen's outline: edges of one triangle only
    edges = np.sort(np.vstack([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    unique, count = np.unique(edges, axis=0, return_counts=True)
    outline = scale * x0[unique[count == 1]][:, :, :2]
    ax.add_collection(LineCollection(outline, colors="0.5", linestyles="--", linewidths=0.6))
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])


def _number(text) -> float:
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def dc_figure(records: list[dict]):
    """Drape coefficient [%] against the bending length c = (B/W)^(1/3) [cm], one point per run;
    measured values (``measured.DC``) beside the computed ones. ``None`` if no run has a DC."""
    c = np.array([100.0 * _number(r.get("bending_length_m")) for r in records])
    dc = np.array([_number(r.get("DC_percent")) for r in records])
    measured = np.array([_number(r.get("measured.DC")) for r in records])
    sim = np.isfinite(c) & np.isfinite(dc)
    if not sim.any():
        return None
    fig = new_figure((5.5, 4.0))
    ax = fig.add_subplot()
    ax.plot(c[sim], dc[sim], "o", color="tab:blue", label="computed")
    meas = np.isfinite(c) & np.isfinite(measured)
    if meas.any():
        ax.plot(c[meas], measured[meas], "s", mfc="none", color="tab:red", label="measured")
        both = meas & sim
        for ci, a, b in zip(c[both], dc[both], measured[both]):
            ax.plot([ci, ci], [a, b], "-", color="0.7", lw=0.8, zorder=0)
    if sim.sum() <= 20:
        for ci, d, r in zip(c[sim], dc[sim], np.array(records, dtype=object)[sim]):
            ax.annotate(r["name"], (ci, d), xytext=(4, 3), textcoords="offset points", fontsize=7)
    ax.margins(x=0.1, y=0.08)   # room for the run names
    ax.set_xlabel("bending length c = (B/W)$^{1/3}$ [cm]")
    ax.set_ylabel("drape coefficient DC [%]")
    ax.grid(alpha=0.3)
    ax.legend()
    return fig


def history_figure(history_csv):
    """Kinetic and strain energy against time from a run's ``history.csv`` (None if empty)."""
    with open(history_csv, newline="") as fh:
        rows = list(csv.DictReader(fh))
    if not rows:
        return None
    t = np.array([_number(r["t"]) for r in rows])
    fig = new_figure((5.5, 3.2))
    ax = fig.add_subplot()
    for key in ("kinetic", "strain"):
        if key in rows[0]:
            y = np.array([_number(r[key]) for r in rows])
            ok = y > 0
            if ok.any():
                ax.semilogy(t[ok], y[ok], label=f"{key} energy")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("[J]")
    ax.grid(alpha=0.3)
    if ax.get_lines():
        ax.legend()
    return fig


# --------------------------------------------------------------------------- HTML
def _e(value) -> str:
    return html.escape(str(value), quote=True)


def _fmt(value) -> str:
    x = _number(value)
    if value in (None, "") or not math.isfinite(x) or isinstance(value, bool):
        return _e("" if value is None else value)
    if float(x).is_integer() and abs(x) < 1e6:
        return _e(int(x))
    return _e(f"{x:.4g}")


def _page(title: str, body: list[str]) -> str:
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{_e(title)}</title><style>{_CSS}</style></head>\n<body>\n"
            + "\n".join(body) + "\n</body></html>\n")


def _thumbnail(run_dir: Path, pvd: str | None) -> str:
    vtu = _last_vtu(run_dir, pvd) if run_dir.is_dir() else None
    if vtu is None or not vtu.exists():
        return ""
    return f'<img class="thumb" alt="top view" src="{figure_data_uri(top_view_figure(vtu))}">'


#: Result columns shown in the sweep table, with their headings.
_SHOWN = {"DC_percent": "DC [%]", "nodes": "nodes", "settling_time_s": "settling time [s]",
          "t_final_s": "t final [s]", "wall_time_s": "wall time [s]"}


def _in_sweep_order(records: list[dict], definition: dict | None) -> list[dict]:
    if not definition:
        return records
    order = {row["name"]: i for i, row in enumerate(definition["rows"])}
    return sorted(records, key=lambda r: order.get(r["name"], len(order)))


def sweep_report(out_dir) -> str:
    """HTML of the report of a sweep folder (``results.csv``, ``sweep.json``, ``runs/``)."""
    out_dir = Path(out_dir)
    path = out_dir / "sweep.json"
    definition = json.loads(path.read_text()) if path.exists() else None
    records = _in_sweep_order(read_results(out_dir / "results.csv"), definition)
    planned = len(definition["rows"]) if definition else len(records)
    inputs = [k for k in (records[0].keys() if records else []) if k != "name"
              and k not in RESULT_COLUMNS]
    good = sum(r["status"] in GOOD for r in records)
    case = f"Base case <code>{_e(definition['case'])}</code>: " if definition else ""
    body = [f"<h1>Sweep {_e(out_dir.name)}</h1>",
            f"<p>{case}{len(records)} of {planned} runs finished, {good} completed or "
            "settled.</p>", "<h2>Drape coefficient and bending length</h2>"]
    fig = dc_figure(records)
    body.append(f'<img alt="DC against bending length" src="{figure_data_uri(fig, dpi=100)}">' if fig
                else '<p class="note">No run has a drape coefficient (Cusick runs have one).</p>')
    if (out_dir / "ensemble.json").exists():
        body += _ensemble_table(json.loads((out_dir / "ensemble.json").read_text()))
    head = ["name", "top view", *inputs, "status", *_SHOWN.values(), "c [cm]", "reason", "files"]
    body += ["<h2>Results</h2>", "<table>", "<tr>" + "".join(f"<th>{_e(h)}</th>" for h in head)
             + "</tr>"]
    for r in records:
        rel = r.get("run_dir") or f"runs/{r['name']}"
        run_dir = out_dir / rel
        links = [f'<a href="{_e(rel)}/">folder</a>'] if run_dir.is_dir() else []
        if r.get("pvd") and (run_dir / r["pvd"]).exists():
            links.append(f'<a href="{_e(rel + "/" + r["pvd"])}">PVD</a>')
        if (run_dir / "report.html").exists():
            links.append(f'<a href="{_e(rel + "/report.html")}">report</a>')
        cells = ([f'<td class="text">{_e(r["name"])}</td>',
                  f"<td>{_thumbnail(run_dir, r.get('pvd'))}</td>"]
                 + [f"<td>{_fmt(r.get(k))}</td>" for k in inputs]
                 + [f'<td class="text">{_e(r["status"])}</td>']
                 + [f"<td>{_fmt(r.get(k))}</td>" for k in _SHOWN]
                 + [f"<td>{_fmt(100 * _number(r.get('bending_length_m')))}</td>",
                    f'<td class="text">{_e(r.get("reason", ""))}</td>',
                    f'<td class="text">{" ".join(links)}</td>'])
        cls = "" if r["status"] in GOOD else ' class="bad"'
        body.append(f"<tr{cls}>" + "".join(cells) + "</tr>")
    body.append("</table>")
    body.append('<p class="note">Top views: the deformed fabric from above at its last written '
                "step, coloured by height (dark low, light high); dashed: the flat specimen. "
                "c = (B/W)<sup>1/3</sup> with B the geometric mean of the warp and weft "
                "rigidities of the simulated KES-FB test and W the weight per area.</p>")
    return _page(f"Sweep {out_dir.name}", body)


def _ensemble_table(data: dict) -> list[str]:
    """HTML rows of the seed ensembles (:mod:`drape.batch.ensemble`)."""
    def pm(s):
        if s["mean"] is None:
            return ""
        return _fmt(s["mean"]) + ("" if s["std"] is None else f" ± {_fmt(s['std'])}")

    head = ["ensemble", "seeds finished", "DC [%] mean ± sd", "DC min–max", "nodes mean ± sd",
            "node histogram", "agreement", "measured"]
    out = ["<h2>Seed ensembles</h2>",
           f'<p class="note">Each row run under the seeds of {_e(data["seed_key"])}; sd is the '
           "sample standard deviation.</p>", "<table>",
           "<tr>" + "".join(f"<th>{_e(h)}</th>" for h in head) + "</tr>"]
    for e in data["ensembles"]:
        dc, nodes = e["DC_percent"], e["nodes"]
        span = f"{_fmt(dc['min'])}–{_fmt(dc['max'])}" if dc["min"] is not None else ""
        hist = " ".join(f"{k}: {v}" for k, v in nodes["histogram"].items())
        measured = ", ".join(f"{k} {v}" for k, v in e.get("measured", {}).items())
        cells = [e["name"], f"{e['finished']} / {e['runs']}", pm(dc), span, pm(nodes), hist,
                 nodes["agreement"], measured]
        out.append("<tr>" + "".join(f'<td class="text">{c}</td>' if i in (0, 5, 6, 7) else f"<td>{c}</td>"
                                    for i, c in enumerate(map(_e, cells))) + "</tr>")
    return out + ["</table>"]


def run_report(run_dir) -> str:
    """HTML of the report of one run folder (``summary.json``, ``history.csv``, VTU/PVD)."""
    run_dir = Path(run_dir)
    s = json.loads((run_dir / "summary.json").read_text())
    body = [f"<h1>{_e(s.get('case', run_dir.name))}</h1>",
            f"<p>{_e(s.get('description', ''))}</p>",
            f"<p><b>{_e(s['status'])}</b>: {_e(s.get('reason', ''))}</p>", "<table>"]
    facts = [("material", s.get("material")), ("model", s.get("model")),
             ("t_final [s]", s.get("t_final")), ("settling time [s]", s.get("settling_time")),
             ("steps", s.get("steps")), ("wall time [s]", s.get("wall_time_s"))]
    analysis = s.get("analysis", {})
    facts += [(f"{analysis.get('name', 'analysis')}: {k}", v) for k, v in analysis.items()
              if k != "name" and isinstance(v, (int, float, str)) and not k.endswith("_png")]
    body += [f'<tr><th class="text">{_e(k)}</th><td>{_fmt(v)}</td></tr>' for k, v in facts]
    body.append("</table>")
    vtu = _last_vtu(run_dir, s.get("pvd"))
    if vtu is not None and vtu.exists():
        body.append(f'<figure><img alt="top view" src="{figure_data_uri(top_view_figure(vtu, 4.0))}">'
                    f"<figcaption>top view at t = {_fmt(s.get('t_final'))} s, coloured by "
                    "height</figcaption></figure>")
    if (run_dir / "history.csv").exists():
        fig = history_figure(run_dir / "history.csv")
        if fig is not None:
            body.append(f'<figure><img alt="energies" src="{figure_data_uri(fig, dpi=100)}">'
                        "<figcaption>energies</figcaption></figure>")
    files = [s.get("pvd"), "history.csv", "summary.json", "case.resolved.toml", "run.log"]
    files += [Path(v).name for k, v in analysis.items() if k.endswith("_png") and v]
    links = [f'<a href="{_e(f)}">{_e(f)}</a>' for f in files if f and (run_dir / f).exists()]
    body.append("<p>Files: " + " · ".join(links) + "</p>")
    return _page(str(s.get("case", run_dir.name)), body)


def write_report(out_dir) -> Path:
    """Write ``out_dir/report.html`` for a sweep or a run folder; return its path."""
    out_dir = Path(out_dir)
    if (out_dir / "results.csv").exists():
        text = sweep_report(out_dir)
    elif (out_dir / "summary.json").exists():
        text = run_report(out_dir)
    else:
        raise FileNotFoundError(f"{out_dir}: neither a sweep (results.csv) nor a run "
                                f"(summary.json) folder")
    path = out_dir / "report.html"
    return atomic_write_text(path, text)
