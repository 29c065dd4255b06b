"""VTU/PVD series, history and summary: readable by meshio and pyvista after every step."""
from __future__ import annotations

import csv
import json
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest
import pyvista
from skfem import MeshTri

from drape.models.fields import split_fields
from drape.run.output import OutputSchedule, OutputWriter, read_pvd


@pytest.fixture
def mesh():
    return MeshTri.init_tensor(np.linspace(0, 0.1, 4), np.linspace(0, 0.02, 3))


def step_fields(mesh, t):
    """Displacement w = t x² (point data) and a per-cell curvature (cell data)."""
    x = mesh.p[0]
    disp = np.zeros((mesh.p.shape[1], 3))
    disp[:, 2] = t * x**2
    centres = mesh.p[:, mesh.t].mean(axis=1)
    return {"point_data": {"displacement": disp},
            "cell_data": {"curvature_xx": t * (1 + centres[0]), "moment_xx": 2 * t * np.ones(mesh.t.shape[1])}}


def test_series_reads_back_with_meshio_and_pyvista_after_every_step(tmp_path, mesh):
    writer = OutputWriter(tmp_path, "strip", mesh)
    times = [0.0, 0.5, 1.25]
    for k, t in enumerate(times):
        writer.write_step(t, step_fields(mesh, t))
        # the PVD is valid after each step and lists exactly the steps written so far
        listed = read_pvd(tmp_path / "strip.pvd")
        assert [tt for tt, _ in listed] == times[: k + 1]
        series = pyvista.get_reader(str(tmp_path / "strip.pvd"))
        assert series.number_time_points == k + 1
    writer.close()

    for t, path in read_pvd(tmp_path / "strip.pvd"):
        m = meshio.read(path)
        expected = step_fields(mesh, t)
        np.testing.assert_allclose(m.points[:, :2], mesh.p.T, rtol=0, atol=1e-15)
        np.testing.assert_array_equal(m.cells_dict["triangle"], mesh.t.T)
        np.testing.assert_allclose(m.point_data["displacement"],
                                   expected["point_data"]["displacement"], rtol=1e-15, atol=0)
        np.testing.assert_allclose(m.cell_data["curvature_xx"][0],
                                   expected["cell_data"]["curvature_xx"], rtol=1e-15)

    assert isinstance(pyvista.read(str(tmp_path / "strip.pvd")), pyvista.DataSet | pyvista.MultiBlock)
    reader = pyvista.get_reader(str(tmp_path / "strip.pvd"))
    assert reader.time_values == times
    for i, t in enumerate(times):
        reader.set_active_time_point(i)
        data = reader.read()
        block = data[0] if isinstance(data, pyvista.MultiBlock) else data
        assert block.n_points == mesh.p.shape[1]
        warped = block.warp_by_vector("displacement")
        np.testing.assert_allclose(warped.points[:, 2], t * mesh.p[0] ** 2, rtol=1e-12, atol=1e-15)


def test_pvd_is_well_formed_xml_with_relative_file_names(tmp_path, mesh):
    writer = OutputWriter(tmp_path, "s", mesh)
    writer.write_step(0.1, step_fields(mesh, 0.1))
    root = ET.parse(tmp_path / "s.pvd").getroot()
    assert root.get("type") == "Collection"
    (ds,) = root.iter("DataSet")
    assert ds.get("file") == "s_0000.vtu" and float(ds.get("timestep")) == 0.1
    assert not list(tmp_path.glob("*.tmp")) and not list(tmp_path.glob(".*"))  # no leftovers


def test_field_selection_keeps_displacement_and_rejects_unknown_names(tmp_path, mesh):
    writer = OutputWriter(tmp_path, "s", mesh, fields=["moment_xx"])
    path = writer.write_step(0.0, step_fields(mesh, 1.0))
    m = meshio.read(path)
    assert set(m.point_data) == {"displacement"} and set(m.cell_data) == {"moment_xx"}
    bad = OutputWriter(tmp_path / "b", "s", mesh, fields=["moment_yy"])
    with pytest.raises(ValueError, match=r"output.fields names \['moment_yy'\].*available: "
                                         r"curvature_xx, displacement, moment_xx"):
        bad.write_step(0.0, step_fields(mesh, 1.0))


def test_flat_fields_are_sorted_by_length(mesh):
    n_p, n_c = mesh.p.shape[1], mesh.t.shape[1]
    pd, cd = split_fields({"displacement": np.zeros((n_p, 3)), "k": np.zeros(n_c)}, n_p, n_c)
    assert list(pd) == ["displacement"] and list(cd) == ["k"]
    with pytest.raises(ValueError, match="'q' has leading dimension 5"):
        split_fields({"q": np.zeros(5)}, n_p, n_c)


def test_history_is_flushed_row_by_row_and_summary_is_json(tmp_path, mesh):
    writer = OutputWriter(tmp_path, "s", mesh)
    writer.append_history({"t": 0.0, "kinetic": np.float64(0.0), "step": np.int64(0)})
    # readable before close: flushed
    rows = list(csv.DictReader(open(tmp_path / "history.csv")))
    assert rows == [{"t": "0.0", "kinetic": "0.0", "step": "0"}]
    writer.append_history({"t": 0.1, "kinetic": 1e-3, "step": 1})
    rows = list(csv.DictReader(open(tmp_path / "history.csv")))
    assert float(rows[-1]["kinetic"]) == 1e-3
    writer.write_summary({"status": "failed", "x": np.float32(2.5), "a": np.arange(2)})
    assert json.loads((tmp_path / "summary.json").read_text()) == {
        "status": "failed", "x": 2.5, "a": [0, 1]}
    writer.close()


def test_schedule_every_dt_writes_first_step_past_each_mark():
    s = OutputSchedule(every_dt=0.25)
    times = [0.0, 0.1, 0.2, 0.3, 0.45, 0.5, 0.74, 0.76, 1.0]
    due = [t for i, t in enumerate(times) if s.due(i, t)]
    assert due == [0.0, 0.3, 0.5, 0.76, 1.0]
    # forcing the final step writes it once, and never twice
    assert s.due(9, 1.01, force=True) and not s.due(9, 1.01, force=True)


def test_schedule_rejects_bad_settings():
    with pytest.raises(ValueError, match="output.every_dt = 0"):
        OutputSchedule(every_dt=0)
    with pytest.raises(ValueError, match="output.every = 0"):
        OutputSchedule(every=0)
