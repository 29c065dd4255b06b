"""
A scan measured beside a simulation
===================================

``drape measure`` reads a scanned Cusick drape through the very analysis a simulated drape
goes through: the shadow of the surface's triangles, the drape coefficient, the nodes and the
harmonics of the outline. A scan sits wherever the scanner put it, so the disc centre is
fitted to the flat disc top.

Here the scan is one the model made: a drape of the KES-only cotton shirting of
``cases/cusick_kes.toml`` (shrunk as in the Cusick example: a 3 × 26 mesh, perturbed over 1 s,
stopped at 3 s, so the numbers are illustrative). Its deformed surface, sampled inside every
element, is written as a scanner gives it: one PLY file in millimetres, off the origin, the
disc's top face included. Measured back it must give the simulation's own DC and node count.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import meshio
import numpy as np

from constitutive.bundled import cases_dir
from drape.analyses.scan_measure import measure_scan, plot_top_view
from drape.case import build, load_case
from drape.run import read_checkpoint, run_case
from meshes import circle

shrink = ["mesh.n_radial=3", "mesh.n_circumferential=26", "load.perturbation.duration=1.0",
          "solver.t_end=3.0", "output.every_dt=1.0"]
case = load_case(cases_dir() / "cusick_kes.toml", shrink)
scratch = tempfile.TemporaryDirectory()
out = Path(scratch.name)
simulated = run_case(case, out, quiet=True)["analysis"]

# %%
# The surface of the final state: the displacement of the last step (kept in the run's
# ``checkpoint.npz``) on the model built from the same case, sampled inside every triangle
# (:meth:`~drape.models.KirchhoffLoveShell.deformed_surface`). The shell's elements are a
# triangle soup there, so shared points are merged, as a scanner's mesh is one surface. The
# disc under the specimen's centre is flat at z = 0 (a triangulated 18 cm circle).

u = read_checkpoint(out).state.u
points, triangles = build(case).model.deformed_surface(u)
points, index = np.unique(np.round(points, 9), axis=0, return_inverse=True)
triangles = index.reshape(-1)[triangles]
disc = circle(diameter=0.18, n_rings=4)
disc_points = np.column_stack([disc.p.T, np.zeros(disc.p.shape[1])])
points = np.vstack([points, disc_points])
triangles = np.vstack([triangles, disc.t.T + len(points) - len(disc_points)])

offset = np.array([0.21, -0.08, 0.75])                 # where the scanner's frame put the disc
scan = out / "scan.ply"
meshio.write_points_cells(scan, 1000 * (points + offset), [("triangle", triangles.astype(np.int32))])  # mm

# %%
# Measure it as ``drape measure scan.ply --scale 0.001`` would, and set it beside the
# simulation's summary.

measured = measure_scan(scan, scale=0.001)
drape = measured.descriptors()
print(f"{'':14s}{'simulated':>12s}{'scan':>12s}")
print(f"{'DC [%]':14s}{simulated['drape_coefficient_percent']:12.2f}"
      f"{drape['drape_coefficient_percent']:12.2f}")
print(f"{'nodes':14s}{simulated['n_nodes']:12d}{drape['n_nodes']:12d}")
print(f"scan: {measured.n_vertices} vertices, {measured.n_triangles} triangles; centre "
      f"found at {np.round(1000 * np.array(drape['centre_m']), 2)} mm "
      f"(put at {1000 * offset[:2]} mm, from the {drape['centre_from']})")

# %%
# The scan's top view, where the scanner put it, and the harmonic amplitudes ``a_k`` of the
# two outlines ``r(θ)``: they do not depend on where the folds sit round the disc, so they
# compare a scan and a simulation whatever their orientation (``a_0``, the mean radius, is
# left out).

top_view = plot_top_view(measured.result, out / "scan_top.png", title="scan.ply, measured")
k = np.arange(1, len(drape["outline_harmonics_m"]))
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.6), width_ratios=[1, 1.3])
ax1.imshow(plt.imread(top_view))
ax1.set_axis_off()
ax2.bar(k - 0.2, 1e3 * np.array(simulated["outline_harmonics_m"][1:]), 0.4, label="simulated")
ax2.bar(k + 0.2, 1e3 * np.array(drape["outline_harmonics_m"][1:]), 0.4, label="scan, measured")
ax2.set_xlabel("harmonic k of the outline r(θ)")
ax2.set_ylabel("amplitude a_k [mm]")
ax2.set_xticks(k[1::2])
ax2.legend()
fig.tight_layout()
plt.show()
