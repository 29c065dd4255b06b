"""
The Peirce cantilever
=====================

The cantilever test (Peirce; ASTM D1388) slides a strip over the edge of a platform until its
tip, seen from the side, lies on a line 41.5° below the platform; half the overhang is then
the bending length ``c``, and ``G = W c³`` the flexural rigidity, W the weight per area.

``cases/cantilever.toml`` clamps a 2.5 cm wide strip of Fabric 1 (warp) at x = 0 with an
overhang of 1.63 cm, lets gravity on over 0.2 s and runs until the strip has settled (the
static out-of-balance force below 10⁻³ of the weight for 5 steps). It is the command-line run
``drape run cases/cantilever.toml``, here through :func:`drape.run.run_case`.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import meshio
import numpy as np

from constitutive.bundled import cases_dir
from drape.case import load_case
from drape.run import read_history, read_pvd, run_case

case = load_case(cases_dir() / "cantilever.toml")      # the bundled cases/ folder
scratch = tempfile.TemporaryDirectory()                 # `drape run` would write out/cantilever/
out = Path(scratch.name)
summary = run_case(case, out, quiet=True)
print(f"{summary['status']}: {summary['reason']}")
for key in ("chord_angle_deg", "bending_length_m", "flexural_rigidity_Nm", "B_kes_Nm",
            "G_over_B_kes"):
    print(f"{key:22s} {summary['analysis'][key]:.4g}")

# %%
# The run folder holds what the command line writes: a VTU per output step and their PVD,
# ``history.csv``, ``summary.json``, ``case.resolved.toml`` and ``checkpoint.npz``.

print(sorted(p.name for p in out.iterdir() if p.suffix != ".vtu" and not p.name.startswith(".")))

# %%
# The settled strip from the side, with the chord from the clamp to the tip: the overhang was
# chosen so that the chord meets the 41.5° line. The history shows the tip's drop and the
# out-of-balance force that the settling rule watches.

t_last, vtu = read_pvd(out / "cantilever.pvd")[-1]
grid = meshio.read(vtu)
x = grid.points + grid.point_data["displacement"]
edge = np.isclose(grid.points[:, 1], grid.points[:, 1].min())     # one long edge of the strip
order = np.argsort(grid.points[edge, 0])
xs, zs = 100 * x[edge, 0][order], 100 * x[edge, 2][order]          # cm

history = read_history(out / "history.csv")
t = np.array([row["t"] for row in history])
tip = np.array([row["tip_uz"] for row in history])
balance = np.array([row["out_of_balance"] or np.nan for row in history], dtype=float)

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
length = 100 * case.mesh.length
ax1.plot([0, length], [0, 0], color="0.7", lw=3, label="flat strip")
ax1.plot(xs, zs, "o-", color="tab:blue", label=f"settled, t = {t_last:.2f} s")
ax1.plot([0, xs[-1]], [0, zs[-1]], "--", color="tab:red",
         label=f"chord, {summary['analysis']['chord_angle_deg']:.1f}°")
line = np.tan(np.radians(41.5)) * np.array([0, length])
ax1.plot([0, length], -line, ":", color="k", label="41.5° line")
ax1.set_aspect("equal")
ax1.set_xlabel("x [cm]")
ax1.set_ylabel("z [cm]")
ax1.legend(fontsize=8)
ax2.plot(t, 1e3 * tip, color="tab:blue")
ax2.set_xlabel("t [s]")
ax2.set_ylabel("tip displacement u_z [mm]", color="tab:blue")
ax3 = ax2.twinx()
ax3.semilogy(t, balance, ".", color="tab:red", ms=4)
ax3.axhline(1e-3, color="tab:red", lw=0.6, ls="--")
ax3.set_ylabel("out-of-balance / weight", color="tab:red")
ax2.set_title(f"settled in {summary['steps']} steps")
fig.tight_layout()
plt.show()
