"""
A catalogue on Dask
===================

A sweep turns one base case into many ordinary runs: one per row of a run table (a CSV file
with a ``name`` column and case keys as columns) or of a grid of values. Each row runs as a
Dask task, on a local cluster of single-threaded worker processes or on an existing cluster
(``scheduler=``), into its own folder ``runs/<name>/``; ``results.csv`` gets a row as each
run finishes, and ``report.html`` shows them all. ``drape sweep`` is the same from the command
line.

The catalogue here is small and fast: the Peirce cantilever of ``cases/cantilever.toml`` with
its bending rigidity scaled (``material.bending_scale``), and once without friction. As an
operator slides a stiffer strip further out to reach the 41.5° line, each row scales the
overhang (``mesh.length``) with the cube root of the rigidity. The Peirce reading should then
give each fabric's own bending length ``c = (B/W)^(1/3)``, W the weight per area and B the
rigidity of the simulated KES-FB test. (``cases/kes_catalogue.csv`` with
``cases/cusick_kes.toml`` is the Cusick catalogue of eight fabrics by their KES values; it
takes minutes per row.)
"""

import json
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from constitutive.bundled import cases_dir
from drape.batch import read_results, run_sweep, write_report
from drape.batch.rows import read_table

scratch = tempfile.TemporaryDirectory()
out = Path(scratch.name)
rows = ["name,material.bending_scale,mesh.length,material.friction"]
for name, scale, friction in [("half", 0.5, ""), ("base", 1, ""), ("double", 2, ""),
                              ("frictionless", 1, "false")]:
    rows.append(f"{name},{scale},{1.63 * scale ** (1 / 3):.3f} cm,{friction}")
(out / "runs.csv").write_text("\n".join(rows) + "\n")
print((out / "runs.csv").read_text())

run_sweep(cases_dir() / "cantilever.toml", read_table(out / "runs.csv"), out / "sweep",
          workers=2, quiet=True)

# %%
# ``results.csv`` has a row per run: its inputs, status, the quantities every analysis shares
# (among them the warp's rigidity ``B_warp_Nm`` and the weight ``weight_N_per_m2``) and where
# its output is. A failing row would say why in its ``reason`` column and leave the others
# running. What is particular to an analysis, here the Peirce reading, is in each run's
# ``summary.json``.

results = read_results(out / "sweep" / "results.csv")
c_fabric, c_peirce = [], []
for r in results:
    summary = json.loads((out / "sweep" / r["run_dir"] / "summary.json").read_text())
    c_fabric.append(100 * (float(r["B_warp_Nm"]) / float(r["weight_N_per_m2"])) ** (1 / 3))
    c_peirce.append(100 * summary["analysis"]["bending_length_m"])
    print(f"{r['name']:13s} {r['status']:8s} (B/W)^(1/3) = {c_fabric[-1]:.3f} cm, "
          f"Peirce c = {c_peirce[-1]:.3f} cm")
report = write_report(out / "sweep")
print(f"{report.name}: {report.stat().st_size // 1024} kB, pictures inline")

# %%
# The Peirce reading against the fabric's own bending length: the simulated test reads it
# within 2 % on every row, frictionless or not.

fig, ax = plt.subplots(figsize=(5.5, 4.5))
line = np.array([min(c_fabric) * 0.95, max(c_fabric) * 1.05])
ax.plot(line, line, color="0.6", lw=1, label="Peirce c = (B/W)^(1/3)")
for r, x, y in zip(results, c_fabric, c_peirce):
    ax.plot(x, y, "o")
    ax.annotate(r["name"], (x, y), textcoords="offset points", xytext=(6, -10), fontsize=8)
ax.set_xlabel("fabric's (B/W)^(1/3) [cm]")
ax.set_ylabel("Peirce bending length c [cm]")
ax.set_aspect("equal")
ax.grid(alpha=0.3)
ax.legend(loc="upper left")
fig.tight_layout()
plt.show()
