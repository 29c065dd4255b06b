"""Pictures of the contact cases for the README (docs/figures/contact_*.png).

Runs each case (or reads a finished run with --runs DIR, holding one folder per case) and
renders its last step with its bodies, off-screen (pyvista):

    python benchmarks/contact_figures.py --out docs/figures
    python benchmarks/contact_figures.py --runs out --out docs/figures     # runs already made
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: case -> camera: the drapes and the fold from above and aside, the tester from the side.
VIEWS = {"table_drape": "isometric", "sphere_drape": "isometric", "drop_fold": "isometric",
         "peirce_platform": "xz"}


def _step(folder) -> int:
    """The output step to show: the last, or for the Peirce tester the one nearest the time
    its tip met the 41.5° line."""
    import json

    from drape.run.output import read_pvd
    from drape.run.pictures import find_pvd

    summary = Path(folder) / "summary.json"
    if not summary.is_file():
        return -1
    analysis = json.loads(summary.read_text()).get("analysis", {})
    if analysis.get("time_s") is None:
        return -1
    times = [t for t, _ in read_pvd(find_pvd(folder))]
    return min(range(len(times)), key=lambda k: abs(times[k] - analysis["time_s"]))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "docs" / "figures"), help="folder for the PNGs")
    parser.add_argument("--runs", help="folder holding a finished run per case (else they are run)")
    parser.add_argument("--cases", nargs="*", default=list(VIEWS), help="which cases")
    args = parser.parse_args(argv)
    os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")
    import pyvista

    pyvista.OFF_SCREEN = True
    from drape.run.pictures import contact_bodies, render_step
    from drape.cli.run import main as run

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name in args.cases:
        folder = Path(args.runs) / name if args.runs else ROOT / "out" / name
        if not args.runs:
            code = run([str(ROOT / "cases" / f"{name}.toml"), "--out", str(folder)])
            if code != 0:
                print(f"{name}: the run ended with exit code {code}", file=sys.stderr)
                return code
        png = render_step(folder, "displacement", _step(folder), out=out / f"contact_{name}.png",
                          window_size=(900, 560), bodies=contact_bodies(folder), view=VIEWS[name])
        print(png)
    return 0


if __name__ == "__main__":
    sys.exit(main())
