"""An identification from its definition: the base case checked, the search run on Dask, the
outputs written.

A definition (``DIR/identify.json``, :data:`DEFINITION`) holds the scans, the base case and its
``--set`` items, the free parameters and their box, the seeds, the budget and the libraries;
``python -m drape.identify`` (:mod:`drape.cli.identify`) makes it from its options.
:func:`identify` checks it (:func:`drape.identification.definition.check_definition`), reads
the scans and checks the base case before DIR is made, then writes into DIR the definition,
``identified.json``, ``material.toml``, ``report.html``, the forward runs (``runs/``) and the
evaluation store (``evaluations.jsonl``, ``evaluations.csv``).
"""
from __future__ import annotations

import logging
import os
import sys
import time
from pathlib import Path

from tqdm import tqdm

from drape.batch.sweep import open_client
from drape.case.case import dump_case, load_case
from drape.identification.definition import DEFINITION, check_definition, write_definition
from drape.identification.forward import ForwardRuns
from drape.identification.outputs import finish
from drape.identification.parameters import full_point, overrides
from drape.identification.search import CONVERGED_WITHIN, Search, run_search
from drape.identification.store import BUNDLED_LIBRARY, fingerprint
from drape.identification.surrogate import design
from drape.identification.target import scan_drapes
from drape.run.lock import folder_lock

__all__ = ["DEFINITION", "check_setup", "quiet_dask", "identify"]


def check_setup(definition: dict):
    """The base case checked (a KES-only Cusick case whose box corners validate); its ``--set``
    items with the weight, the weight (mg/cm²), the thickness, the set-up's fingerprint and the
    box.

    Raises
    ------
    ValueError
        The base case is no KES-only Cusick case, or a corner of the box is no valid fabric.
    """
    case = load_case(definition["base"], definition["set"])
    if case.case.analysis != "cusick" or case.material.kes is None:
        raise ValueError(f"--base {definition['base']}: needs a Cusick case with [material.kes] "
                         "(e.g. cases/cusick_kes.toml)")
    given = definition["weight"] is not None
    weight = definition["weight"] if given else float(case.material.kes.weight)
    base = list(definition["set"]) + ([f"material.kes.weight={weight:g}"] if given else [])
    box = {k: tuple(v) for k, v in definition["box"].items()}
    for corner in design(box, 0):
        items = base + overrides(full_point(corner, list(box)), weight)
        try:
            load_case(definition["base"], items)
        except ValueError as exc:
            where = ", ".join(f"{k} = {v:g}" for k, v in corner.items())
            raise ValueError(f"--box: the corner {where} is not a valid fabric at W = {weight:g} "
                             f"mg/cm² ({' '.join(str(exc).split())}); narrow --box") from None
    setup = fingerprint(dump_case(load_case(definition["base"], base)), [], weight)
    return base, weight, case.material.kes.thickness, setup, box


def quiet_dask() -> None:
    """Dask's own warnings off the console (here and in the workers it starts): a cancelled
    run at the end is expected, and the tool's errors are its one line."""
    os.environ.setdefault("DASK_LOGGING__DISTRIBUTED", "error")
    import distributed  # noqa: F401  (its loggers exist once it is imported)

    for name in ["distributed", *logging.root.manager.loggerDict]:
        if name.startswith("distributed"):
            logging.getLogger(name).setLevel(logging.ERROR)


def _search(definition: dict, out: Path, setup: str, box: dict, target) -> Search:
    """The search of ``definition`` in ``out``, with its libraries."""
    library = Path(definition["library"]) if definition["library"] else None
    bundled = BUNDLED_LIBRARY if definition.get("bundled_library", False) else None
    return Search(target, box, definition["evaluations"], out, setup, library,
                  definition["design"], bundled=bundled,
                  converged_within=definition.get("converged_within", CONVERGED_WITHIN))


def identify(definition: dict, out, *, scheduler: str | None = None, workers: int | None = None,
             quiet: bool = False) -> dict:
    """Run the identification ``definition`` into ``out`` (forward runs on the Dask cluster at
    ``scheduler``, or on a local one of ``workers`` processes); return ``identified.json``'s
    content.

    Raises
    ------
    drape.identification.search.OutOfReach
        The scans lie beyond what the model reaches over the box.
    ValueError
        The definition, a scan, the base case or the box breaks a rule (nothing is written).
    """
    out = Path(out)
    definition = check_definition(definition)
    t0 = time.perf_counter()
    target, scans = scan_drapes(definition["scans"], scale=definition["scale"])
    read_s = time.perf_counter() - t0
    for warning in (w for m in scans for w in m.warnings):
        print(f"warning: {warning}", file=sys.stderr)
    base, weight, thickness, setup, box = check_setup(definition)
    out.mkdir(parents=True, exist_ok=True)
    with folder_lock(out):
        quiet_dask()
        client, cluster = open_client(scheduler, workers)
        try:
            # stored once the cluster is there: a scheduler that cannot be reached leaves no
            # definition behind that a corrected command would have to --resume
            write_definition(out, definition)
            search = _search(definition, out, setup, box, target)
            search.seconds["io"] += read_s
            n_workers = max(1, len(client.scheduler_info()["workers"]))
            forward = ForwardRuns(client, definition["base"], base, weight, definition["seeds"],
                                  out / "runs", setup)
            with tqdm(total=definition["evaluations"], disable=quiet, unit="point",
                      desc="evaluations", file=sys.stderr) as bar:
                found = run_search(search, forward, max(1, n_workers // definition["seeds"]), bar)
            return finish(search, found, forward, scans, weight, thickness, definition)
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
