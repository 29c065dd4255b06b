"""Validation of ``drape identify`` on real fabrics: identify from some specimens, predict the others.

    python benchmarks/identify_fabrics.py SCANS.npz --out DIR [--fabrics 1 2 ...]
        [--evaluations 6] [--seeds 2] [--workers 2] [--set KEY=VALUE ...]

``SCANS.npz``: registered scans of real Cusick drapes in the format ``scan_descriptors.py``
reads (keys ``fabricNN_sampleSS_captureC``, ``fabricNN_sampleSS``, ``fabricNN_sampleSS_obsK``,
``vertex_unit_m``), e.g. the Leeds Cusick drape dataset (D. Gong, N. Mao, H. Wang, "Bayesian
Differentiable Physics for Cloth Digitalization", CVPR 2024); the scans are external data.

For each fabric, the scans of its odd samples are the training set: ``drape identify`` finds
the bending length and 2HB/B from them (``cases/cusick_kes.toml`` unless ``--case``; all
fabrics share one growing ``--library`` of forward runs, ``DIR/library``). The identified
point's simulated drapes then predict the even samples' scans: mean DC within 5 points and the
most frequent node count within ±1 (the target), beside the measured spread between those
specimens. Each half holds every capture of its specimens, face up and face down, as a Cusick
test reads a specimen on both faces and takes the mean (BS 5058); ``--faces up`` keeps the
face-up captures (1–2, or the single capture) only. The script also reports, from the scans
alone, face up against face down (captures 1–2 against 3–4; the identified law is symmetric
unless ``--set material.face_down_ratio=...``, so it predicts no difference) and the creep
series (``obsK``: the fall of DC at a fixed node count).

``--library-without-own LIB`` gives each fabric a library of its own: LIB's forward runs less
those its folder made in an earlier run of this script (``DIR/fabricNN/library``), but for the
initial design's, which every search runs first whatever its scans. Each fabric is then
identified as a lab would identify a new fabric after the others (or with the package's
bundled runs, made of the others).

``--scans-alone`` runs nothing: it judges each fabric's training scans as the prediction of its
test scans by the same target: what a model that reproduced its training specimens exactly
would score on that split (``DIR/scans_alone.csv``).

Writes, one row per fabric as soon as it is done: ``DIR/fabrics.csv``; at the end
``DIR/identify_fabrics.md`` and ``DIR/nodes_at_matched_dc.png`` (the plot of
``nodes_at_matched_dc.py``, here with the identified fabrics).
"""
from __future__ import annotations

import argparse
import csv
import os
import re
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from drape.cli.identify import main as identify  # noqa: E402
from identifiability import add_forward_options  # noqa: E402
from drape.identification.objective import misfit  # noqa: E402
from drape.identification.parameters import DEFAULT_FREE, parse_box  # noqa: E402
from drape.identification.store import append_evaluation, read_evaluations  # noqa: E402
from drape.identification.surrogate import design  # noqa: E402

KEY = re.compile(r"fabric(?P<fabric>\d+)_sample(?P<sample>\d+)(?:_(?P<series>capture|obs)(?P<n>\d+))?$")
COLUMNS = ["fabric", "train", "test", "status", "bending_length_cm", "interval_c",
           "hysteresis_per_cm", "interval_h", "train_DC", "test_DC", "test_DC_sd", "model_DC",
           "dDC", "test_nodes", "test_mode", "model_nodes", "model_mode", "DC_within_5",
           "mode_within_1", "J_train", "J_test", "spectrum_test", "matched", "face_up_DC",
           "face_down_DC", "wall_s"]


def write_scans(npz: Path, folder: Path) -> dict:
    """Every scan of the file as a PLY in ``folder``; ``{key: path}``."""
    import meshio

    data = np.load(npz)
    unit = float(data["vertex_unit_m"])
    folder.mkdir(parents=True, exist_ok=True)
    out = {}
    for name in data.files:
        if not name.endswith("/vertices"):
            continue
        key = name[: -len("/vertices")]
        path = folder / f"{key}.ply"
        if not path.exists():
            meshio.write(path, meshio.Mesh(data[name] * unit,
                                           [("triangle", data[f"{key}/faces"].astype(np.int32))]))
        out[key] = path
    return out


def split(scans: dict, faces: str = "both") -> dict:
    """Per fabric: training (odd samples), test (even samples), face down, creep series.

    ``faces="both"``: every capture of a specimen, face up and face down, goes to its half, as a
    Cusick test reads a specimen on both faces and takes the mean (BS 5058); ``"up"``: the face-up
    captures (1–2, or the single capture) only. ``down`` lists the face-down captures either way.
    """
    if faces not in ("both", "up"):
        raise ValueError(f"faces must be 'both' or 'up', not {faces!r}")
    fabrics = defaultdict(lambda: {"train": [], "test": [], "down": [], "creep": []})
    for key, path in sorted(scans.items()):
        m = KEY.match(key)
        if not m:
            continue
        f = fabrics[int(m["fabric"])]
        if m["series"] == "obs":
            f["creep"].append((int(m["sample"]), int(m["n"]), path))
            continue
        half = "train" if int(m["sample"]) % 2 else "test"
        if m["series"] == "capture" and int(m["n"]) > 2:
            f["down"].append(path)
            if faces == "up":
                continue
        f[half].append(path)
    return dict(sorted(fabrics.items()))


def _measure(paths):
    from drape.identification.target import scan_drapes

    return scan_drapes(paths)[0]


def scans_alone(fabrics: dict) -> list[dict]:
    """What the scans themselves allow: each fabric's training specimens, as their own
    prediction of its test specimens (their mean DC, their most frequent node count), judged by
    the same target as an identified model. Where the two halves differ by more than the
    target, a model that reproduces its training specimens exactly misses it."""
    rows = []
    for number, parts in fabrics.items():
        if not (parts["train"] and parts["test"]):
            continue
        train, test = _measure(parts["train"]), _measure(parts["test"])
        rows.append({"fabric": number, "train_DC": round(float(train.dc.mean()), 2),
                     "test_DC": round(float(test.dc.mean()), 2),
                     "train_nodes": " ".join(map(str, train.nodes)), "train_mode": train.nodes_mode(),
                     "test_nodes": " ".join(map(str, test.nodes)), "test_mode": test.nodes_mode(),
                     **judged(train, test)})
    return rows


def judged(predicted, test) -> dict:
    """The target on a fabric's test specimens: the predicted drapes' mean DC within 5 points
    of theirs, and the predicted most frequent node count within ±1 of theirs."""
    dDC = float(predicted.dc.mean() - test.dc.mean())
    return {"dDC": round(dDC, 2), "DC_within_5": abs(dDC) <= 5.0,
            "mode_within_1": abs(predicted.nodes_mode() - test.nodes_mode()) <= 1}


def without_own(source: Path, library: Path, folder: str) -> int:
    """Write to ``library`` the evaluations of the library ``source`` that no run of ``folder``
    (a fabric's folder of this script) made, and those at the initial design's points whoever
    made them; return how many.

    The initial design (the box's corners and Latin-hypercube points of a fixed seed,
    :func:`drape.identification.surrogate.design`) is the same for every fabric and does not
    depend on its scans: a library that the other fabrics made holds it whichever fabric ran it
    first."""
    initial = design(parse_box([], list(DEFAULT_FREE)), 2 * len(DEFAULT_FREE))

    def at_design(e) -> bool:
        return any(all(k in e.point and np.isclose(e.point[k], q[k], rtol=1e-5, atol=0) for k in q)
                   for q in initial)

    kept = [e for e in read_evaluations(source)
            if at_design(e)
            or not any(Path(r.get("run_dir") or "").parts[-4:-3] == (folder,) for r in e.runs)]
    library.mkdir(parents=True, exist_ok=True)
    for e in kept:
        append_evaluation(library, e)
    return len(kept)


def face_dcs(parts: dict, train, test) -> tuple[float, float]:
    """Mean DC of a fabric's face-up and of its face-down captures, each scan measured once:
    those of the halves are in ``train`` and ``test`` already (with ``--faces up`` the
    face-down ones are in neither)."""
    dc = dict(zip(parts["train"] + parts["test"], np.concatenate([train.dc, test.dc])))
    missing = [q for q in parts["down"] if q not in dc]
    dc.update(zip(missing, _measure(missing).dc) if missing else ())
    up = [v for q, v in dc.items() if q not in parts["down"]]
    return round(float(np.mean(up)), 2), round(float(np.mean([dc[q] for q in parts["down"]])), 2)


def run_fabric(number: int, parts: dict, args, out: Path, first: bool, library: Path | None = None) -> dict:
    """Identify one fabric from its training scans; compare with its test scans."""
    import json
    import time

    folder = out / f"fabric{number:02d}"
    t0 = time.perf_counter()
    stored = folder / "identify.json"     # a resumed fabric keeps the budget it started with
    budget = (json.loads(stored.read_text())["evaluations"] if stored.exists()
              else args.first_evaluations if first else args.evaluations)
    argv = [*map(str, parts["train"]), "--base", args.case, "--out", str(folder),
            "--evaluations", str(budget), "--seeds", str(args.seeds),
            "--library", str(library or out / "library"), "--no-bundled-library", "--quiet"]
    argv += ["--workers", str(args.workers)] if args.workers else []
    argv += [] if args.converged_within is None else ["--converged-within", str(args.converged_within)]
    argv += sum((["--set", s] for s in args.overrides), [])
    if stored.exists():
        argv.append("--resume")
    code = identify(argv)
    if code in (130, 143):              # stopped: the next call continues it (--resume)
        raise KeyboardInterrupt
    train, test = _measure(parts["train"]), _measure(parts["test"])
    row = {"fabric": number, "train": len(train), "test": len(test),
           "train_DC": round(float(train.dc.mean()), 2), "test_DC": round(float(test.dc.mean()), 2),
           "test_DC_sd": round(test.dc_std(), 2), "test_nodes": " ".join(map(str, test.nodes)),
           "test_mode": test.nodes_mode(), "wall_s": round(time.perf_counter() - t0, 1)}
    if parts["down"]:
        row.update(zip(("face_up_DC", "face_down_DC"), face_dcs(parts, train, test)))
    if code != 0:
        return {**row, "status": {5: "out of reach"}.get(code, f"exit {code}")}
    result = json.loads((folder / "identified.json").read_text())
    final = [e for e in read_evaluations(folder) if e.name.startswith("identified")][-1].drapes
    c, h = result["parameters"]["bending_length"], result["parameters"]["hysteresis"]
    iv = result["intervals"]
    row.update(status="identified", bending_length_cm=round(c, 3), hysteresis_per_cm=round(h, 3),
               interval_c=f"{iv['bending_length']['low']:.3g}-{iv['bending_length']['high']:.3g}",
               interval_h=f"{iv['hysteresis']['low']:.3g}-{iv['hysteresis']['high']:.3g}",
               model_DC=round(float(final.dc.mean()), 2),
               model_nodes=" ".join(map(str, final.nodes)), model_mode=final.nodes_mode(),
               **judged(final, test))
    m = misfit(test, final)
    row.update(J_test=round(m.J, 2), spectrum_test=round(m["spectrum"], 2),
               J_train=round(result["misfit"]["J"], 2), matched=result["matched"])
    return row


def creep_table(fabrics: dict) -> list[str]:
    """The creep series from the scans: DC and nodes per observation."""
    lines = []
    for number, parts in fabrics.items():
        by_obs = defaultdict(list)
        for _, n, path in parts["creep"]:
            by_obs[n].append(path)
        for n in sorted(by_obs):
            d = _measure(by_obs[n])
            lines.append(f"| {number} | {n} | {d.dc.mean():.1f} ± {d.dc_std():.1f} | "
                         f"{' '.join(map(str, d.nodes))} |")
    return lines


def markdown(rows: list[dict], creep: list[str]) -> str:
    head = ["| fabric | c (cm) [interval] | 2HB/B (1/cm) [interval] | test DC % (sd) | model DC % "
            "| ΔDC | test nodes (mode) | model nodes (mode) | J train / test | ok | face up / down DC % |",
            "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        fud = f"{r.get('face_up_DC', '')} / {r.get('face_down_DC', '')}" if r.get("face_down_DC") else "–"
        if r["status"] != "identified":
            head.append(f"| {r['fabric']} | {r['status']} | | {r['test_DC']} ({r['test_DC_sd']}) | "
                        f"| | {r['test_nodes']} ({r['test_mode']}) | | | no | {fud} |")
            continue
        ok = "yes" if r["DC_within_5"] and r["mode_within_1"] else "no"
        head.append(f"| {r['fabric']} | {r['bending_length_cm']} [{r['interval_c']}] | "
                    f"{r['hysteresis_per_cm']} [{r['interval_h']}] | {r['test_DC']} ({r['test_DC_sd']}) | "
                    f"{r['model_DC']} | {r['dDC']:+.1f} | {r['test_nodes']} ({r['test_mode']}) | "
                    f"{r['model_nodes']} ({r['model_mode']}) | {r['J_train']} / {r['J_test']} | "
                    f"{ok} | {fud} |")
    n_ok = sum(1 for r in rows if r.get("DC_within_5") and r.get("mode_within_1"))
    text = "\n".join(head) + f"\n\n{n_ok} of {len(rows)} fabrics within 5 DC points and ±1 node.\n"
    if creep:
        text += ("\nCreep series (scans): | fabric | observation | DC % | nodes |\n|---|---|---|---|\n"
                 + "\n".join(creep) + "\n")
    return text


def plot(rows: list[dict], path: Path) -> None:
    """Node count against DC (the plot of nodes_at_matched_dc.py): measured test ranges, model."""
    from nodes_at_matched_dc import plot as matched_plot

    table = []
    for r in rows:
        if r["status"] != "identified":
            continue
        nodes = list(map(int, r["test_nodes"].split()))
        table.append({"law": "tensor", "measured_DC": r["test_DC"], "measured_nodes_min": min(nodes),
                      "measured_nodes_max": max(nodes), "model_DC": r["model_DC"],
                      "model_nodes": r["model_nodes"]})
    if table:
        matched_plot(table, path)


def _typed(row: dict) -> dict:
    """A fabrics.csv row with its numbers and flags read back."""
    out = dict(row)
    for k, v in row.items():
        if v in ("True", "False"):
            out[k] = v == "True"
        elif k not in ("test_nodes", "model_nodes", "interval_c", "interval_h", "status"):
            try:
                out[k] = float(v) if "." in v else int(v)
            except (TypeError, ValueError):
                pass
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scans", type=Path, help="registered scans (.npz)")
    p.add_argument("--out", type=Path, default=Path("out/identify_fabrics"))
    p.add_argument("--fabrics", type=int, nargs="+",
                   help="fabric numbers, run in this order (default: all, in numbers' order)")
    p.add_argument("--evaluations", type=int, default=6,
                   help="points per fabric once the library has some (default 6)")
    p.add_argument("--first-evaluations", type=int, default=12,
                   help="points of a fabric that starts an empty library (default 12)")
    p.add_argument("--converged-within", type=float, default=None, metavar="W",
                   help="drape identify's convergence stop (default: its own; 0: spend every evaluation)")
    p.add_argument("--library-without-own", type=Path, metavar="LIB",
                   help="give each fabric a library of its own, LIB's forward runs less those of "
                        "that fabric's folder (fabricNN) in an earlier run of this script: every "
                        "fabric is new to a lab that has identified the others")
    p.add_argument("--faces", choices=("both", "up"), default="both",
                   help="captures in each half: every capture of a specimen, face up and face down "
                        "(default, as BS 5058 reads a specimen), or the face-up ones only")
    p.add_argument("--scans-alone", action="store_true",
                   help="no identification: each fabric's training scans as the prediction of its "
                        "test scans, by the same target (DIR/scans_alone.csv)")
    add_forward_options(p)
    args = p.parse_args(argv)
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    args.out.mkdir(parents=True, exist_ok=True)
    fabrics = split(write_scans(args.scans, args.out / "scans"), args.faces)
    if args.fabrics:                    # in the order given: the fabrics wanted first run first
        fabrics = {k: fabrics[k] for k in args.fabrics if k in fabrics}
    if args.scans_alone:
        return _write_scans_alone(scans_alone(fabrics), args.out / "scans_alone.csv")
    table = args.out / "fabrics.csv"
    done = {}
    if table.exists():
        with open(table, newline="") as fh:
            done = {int(r["fabric"]): r for r in csv.DictReader(fh)}
    rows = []
    for number, parts in fabrics.items():
        if number in done:
            continue
        library = args.out / "library"
        if args.library_without_own is not None:
            library = args.out / f"fabric{number:02d}" / "library"
            if not library.exists():
                without_own(args.library_without_own, library, f"fabric{number:02d}")
        started = bool(read_evaluations(library))
        row = run_fabric(number, parts, args, args.out, first=not started, library=library)
        rows.append(row)
        new = not table.exists()
        with open(table, "a", newline="") as fh:
            writer = csv.DictWriter(fh, COLUMNS, extrasaction="ignore")
            if new:
                writer.writeheader()
            writer.writerow(row)
        print(f"fabric {number}: {row['status']}, test DC {row['test_DC']} model "
              f"{row.get('model_DC', '-')}, nodes {row['test_mode']} / {row.get('model_mode', '-')}",
              flush=True)
    with open(table, newline="") as fh:
        rows = [_typed(r) for r in csv.DictReader(fh)]
    text = markdown(rows, creep_table(fabrics))
    (args.out / "identify_fabrics.md").write_text(text)
    plot(rows, args.out / "nodes_at_matched_dc.png")
    print(text)
    return 0


def _write_scans_alone(rows: list[dict], path: Path) -> int:
    with open(path, "w", newline="") as fh:
        writer = csv.DictWriter(fh, list(rows[0]) if rows else ["fabric"])
        writer.writeheader()
        writer.writerows(rows)
    print("| fabric | train DC % | test DC % | ΔDC | train nodes (mode) | test nodes (mode) | within 5 / ±1 |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        ok = f"{'✓' if r['DC_within_5'] else '✗'} / {'✓' if r['mode_within_1'] else '✗'}"
        print(f"| {r['fabric']} | {r['train_DC']} | {r['test_DC']} | {r['dDC']:+.2f} | "
              f"{r['train_nodes']} ({r['train_mode']}) | {r['test_nodes']} ({r['test_mode']}) | {ok} |")
    both = sum(r["DC_within_5"] and r["mode_within_1"] for r in rows)
    print(f"both within target: {both} of {len(rows)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
