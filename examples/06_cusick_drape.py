"""
The Cusick drape test
=====================

In the Cusick drape test (BS 5058, ISO 9073-9) a 30 cm circular specimen hangs from an 18 cm
disc and falls into folds; a drape meter reads its shadow from above. The drape coefficient
``DC`` is the shadow's share of the annulus between the disc and the flat specimen, 0 for a
limp fabric hanging straight down and 1 for a rigid one; the nodes are its folds.

``cases/cusick_fabric1.toml`` puts a specimen of Fabric 1 on the one Cusick set-up
(``cases/setups/cusick.toml``): it lies on a support round the disc, which is lowered away
while a small seeded load breaks the symmetry; then it creeps until it settles (at 21 s, DC
16.0 %, 11 nodes on its 6 × 74 mesh, in a few minutes on 2 cores).

**Shrunk for the gallery.** This example runs the same case on a 3 × 26 mesh, perturbed over
1 s instead of 2, and stops at 3 s of simulated time instead of settling. The
overrides are the ``--set`` items of ``drape run``. Its figures are illustrative: the coarse,
unsettled drape hangs stiffer and in a different number of folds than the converged one.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import pyvista as pv

from constitutive.bundled import cases_dir
from drape.case import load_case
from drape.run import read_pvd, run_case

shrink = ["mesh.n_radial=3", "mesh.n_circumferential=26",     # 26 = 2·13 sectors
          "load.perturbation.duration=1.0", "solver.t_end=3.0", "output.every_dt=0.5"]
case = load_case(cases_dir() / "cusick_fabric1.toml", shrink)
scratch = tempfile.TemporaryDirectory()
out = Path(scratch.name)
summary = run_case(case, out, quiet=True)
drape = summary["analysis"]
print(f"{summary['status']}: {summary['reason']}")
print(f"DC = {drape['drape_coefficient_percent']:.1f} %, {drape['n_nodes']} nodes, "
      f"mean node depth {100 * drape['node_depth_mean_m']:.1f} cm")

# %%
# The drape meter's picture, which the ``cusick`` analysis writes beside the summary
# (``cusick_fabric1_top_view.png``): the shadow, the disc, the flat specimen's outline and
# the crests of the nodes.

fig, ax = plt.subplots(figsize=(6, 6))
ax.imshow(plt.imread(drape["top_view_png"]))
ax.set_axis_off()
plt.show()

# %%
# The deformed specimen at the last output step, read from the run's PVD with pyvista (what
# ``drape inspect`` draws, and what ParaView opens), coloured by the warp curvature.

t, vtu = read_pvd(out / "cusick_fabric1.pvd")[-1]
specimen = pv.read(vtu).warp_by_vector("displacement")
plotter = pv.Plotter()
plotter.add_mesh(specimen, scalars="curvature_xx", cmap="viridis", show_edges=True,
                 scalar_bar_args={"title": "curvature_xx [1/m]"})
plotter.add_mesh(pv.Disc(inner=0.0, outer=0.09, c_res=64), color="lightgrey")   # the disc
plotter.view_isometric()
plotter.camera.elevation = -15
plotter.camera.zoom(1.2)
plotter.show()
