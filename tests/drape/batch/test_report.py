"""The HTML report of a sweep and of a run: self-contained, complete, and rendered by a browser."""
from __future__ import annotations

import base64
import html.parser
import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from drape.batch import report

from drape.batch import rows as sweep_rows
from drape.cli import report as report_cli
from drape.cli import sweep as sweep_cli
from drape.run.output import OutputWriter

ROOT = Path(__file__).resolve().parents[3]
CUSICK = ROOT / "cases" / "cusick_kes.toml"
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def sweep_dir(tmp_path_factory, tiny_cusick):
    """A finished three-row Cusick sweep (one row invalid), with its report written by the sweep."""
    tmp = tmp_path_factory.mktemp("report")
    table = tmp / "catalogue.csv"
    table.write_text("name,material.kes.B_warp,material.kes.B_weft,measured.DC\n"
                     "limp,0.04,0.03,61.5\nstiff,0.3,0.2,\nbroken,-0.1,0.2,50\n")
    out = tmp / "sweep"
    code = sweep_cli.main([str(CUSICK), "--table", str(table), "--out", str(out), "--workers", "1",
                       "--quiet", *sum((["--set", o] for o in tiny_cusick), [])])
    assert code == 0
    return out


class Page(html.parser.HTMLParser):
    """Tags with their attributes, and the text of every table row."""

    def __init__(self, text: str):
        super().__init__()
        self.tags: list[tuple[str, dict]] = []
        self.rows: list[list[str]] = []
        self.row_classes: list[str | None] = []
        self._cell: list[str] | None = None
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        self.tags.append((tag, attrs))
        if tag == "tr":
            self.rows.append([])
            self.row_classes.append(attrs.get("class"))
        elif tag in ("td", "th"):
            self._cell = []

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self.rows[-1].append("".join(self._cell).strip())
            self._cell = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)


def check_self_contained(path: Path) -> Page:
    """Every picture inline as a PNG data URI, every link relative and present, nothing remote."""
    text = path.read_text(encoding="utf-8")
    page = Page(text)
    assert not [t for t, _ in page.tags if t in ("script", "link", "iframe", "object")]
    assert "http://" not in text and "https://" not in text and "url(" not in text
    images = [a["src"] for t, a in page.tags if t == "img"]
    assert images
    for src in images:
        assert src.startswith("data:image/png;base64,")
        assert base64.b64decode(src.split(",", 1)[1]).startswith(PNG_MAGIC)
    for href in (a["href"] for t, a in page.tags if t == "a"):
        assert not href.startswith(("/", "file:")) and "//" not in href
        assert (path.parent / href).exists(), href
    return page


def test_sweep_report_lists_every_run_with_top_view_and_pvd(sweep_dir):
    records = sweep_rows.read_results(sweep_dir / "results.csv")
    page = check_self_contained(sweep_dir / "report.html")
    head, *rows = page.rows
    assert [r[0] for r in rows] == ["limp", "stiff", "broken"]      # the table's order
    by_name = dict(zip((r[0] for r in rows), rows))
    by_record = {r["name"]: r for r in records}
    dc = head.index("DC [%]")
    for name in ("limp", "stiff"):
        assert by_record[name]["status"] == "completed"
        assert float(by_name[name][dc]) == pytest.approx(float(by_record[name]["DC_percent"]),
                                                         rel=1e-3)
    broken = by_name["broken"]
    assert by_record["broken"]["status"] == "invalid"
    assert by_record["broken"]["reason"] in broken
    assert page.row_classes[1:] == [None, None, "bad"]
    pvd_links = [a["href"] for t, a in page.tags if t == "a" and a["href"].endswith(".pvd")]
    assert pvd_links == ["runs/limp/cusick_kes.pvd", "runs/stiff/cusick_kes.pvd"]
    thumbs = [a for t, a in page.tags if t == "img" and a.get("class") == "thumb"]
    assert len(thumbs) == 2                     # the invalid row has nothing to show
    plots = [a for t, a in page.tags if t == "img" and a.get("alt", "").startswith("DC")]
    assert len(plots) == 1


def test_run_report_shows_the_summary_and_links_its_files(sweep_dir):
    run = sweep_dir / "runs" / "limp"
    assert report_cli.main([str(run)]) == 0
    page = check_self_contained(run / "report.html")
    summary = json.loads((run / "summary.json").read_text())
    facts = {r[0]: r[1] for r in page.rows if len(r) == 2}
    assert float(facts["cusick: drape_coefficient_percent"]) == pytest.approx(
        summary["analysis"]["drape_coefficient_percent"], rel=1e-3)
    assert int(facts["steps"]) == summary["steps"]
    links = {a["href"] for t, a in page.tags if t == "a"}
    assert {"cusick_kes.pvd", "history.csv", "summary.json", "case.resolved.toml"} <= links


def test_report_of_a_folder_without_results_is_an_error(tmp_path, capsys):
    assert report_cli.main([str(tmp_path)]) == 2
    assert "neither a sweep" in capsys.readouterr().err


def test_dc_figure_draws_each_computed_and_measured_value():
    records = [
        {"name": "a", "bending_length_m": "0.012", "DC_percent": "55.0", "measured.DC": "50"},
        {"name": "b", "bending_length_m": "0.020", "DC_percent": "72.5", "measured.DC": ""},
        {"name": "bad", "bending_length_m": "", "DC_percent": "", "measured.DC": "40"},
        {"name": "c", "bending_length_m": "0.030", "DC_percent": "88.0"},
    ]
    fig = report.dc_figure(records)
    lines = {line.get_label(): line for line in fig.axes[0].get_lines()}
    np.testing.assert_allclose(lines["computed"].get_xdata(), [1.2, 2.0, 3.0], rtol=1e-12)
    np.testing.assert_allclose(lines["computed"].get_ydata(), [55.0, 72.5, 88.0], rtol=1e-12)
    np.testing.assert_allclose(lines["measured"].get_xdata(), [1.2], rtol=1e-12)
    np.testing.assert_allclose(lines["measured"].get_ydata(), [50.0], rtol=1e-12)
    assert report.dc_figure([{"name": "x", "bending_length_m": "0.01", "DC_percent": ""}]) is None


def test_top_view_places_the_deformed_fabric_and_colours_it_by_height(tmp_path):
    from skfem import MeshTri

    mesh = MeshTri.init_tensor(np.linspace(0, 0.1, 3), np.linspace(0, 0.05, 2))
    x, y = mesh.p
    u = np.column_stack([0.01 * x, -0.02 * y, -0.3 * x**2])      # stretched, sheared, drooping
    with OutputWriter(tmp_path, "demo", mesh) as writer:
        writer.write_step(0.0, {"displacement": u})
    fig = report.top_view_figure(tmp_path / "demo_0000.vtu")
    surface = fig.axes[0].collections[0]
    triangulation = surface._triangulation
    np.testing.assert_allclose(triangulation.x, 100 * (x + u[:, 0]), rtol=1e-6)
    np.testing.assert_allclose(triangulation.y, 100 * (y + u[:, 1]), rtol=1e-6)
    np.testing.assert_allclose(surface.get_array(), 100 * u[:, 2], rtol=1e-6, atol=1e-9)


# --------------------------------------------------------------------------- browser
def chromium() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        path = shutil.which(name)
        if path:
            return path
    pytest.fail("no Chromium on PATH: install it (e.g. apt-get install -y chromium) to run the "
                "browser tests")


@pytest.mark.browser
def test_sweep_report_renders_in_headless_chromium(sweep_dir, tmp_path):
    from matplotlib.image import imread

    shot = tmp_path / "report.png"
    proc = subprocess.run([chromium(), "--headless", "--no-sandbox", "--disable-gpu",
                           "--hide-scrollbars", "--window-size=1300,1000",
                           f"--screenshot={shot}", (sweep_dir / "report.html").as_uri()],
                          capture_output=True, text=True, timeout=180)
    assert shot.exists(), proc.stderr
    rgb = imread(shot)[..., :3]
    ink = np.any(rgb < 0.9, axis=-1)                 # anything not (nearly) white
    colour = np.ptp(rgb, axis=-1) > 0.25             # saturated: the plot and the top views
    assert ink.mean() > 0.02, f"only {ink.mean():.2%} of the screenshot is not white"
    assert colour.mean() > 0.005, "no coloured pixels: the inline pictures did not render"
