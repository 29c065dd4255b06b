"""Forward runs bundled with the package: ``cases/libraries/identification``, the warm start of
``drape identify``.

:func:`bundle` takes from library folders (``drape identify --library``) the evaluations run in
the set-up of a bundled base case as it loads now (its fingerprint, :func:`setup_of`: the
resolved case at its own weight, no ``--set``), keeps what the surrogate reads (the point, and
per seed the status and the drape's descriptors; run folders become names, :func:`bundled`),
and appends those whose point the bundle lacks. Every bundled evaluation carries the
fingerprint of a bundled case as it loads now, so a change of the case makes its runs stale.
"""
from __future__ import annotations

from pathlib import Path

from constitutive.bundled import cases_dir
from drape.case.case import dump_case, load_case
from drape.identification.store import Evaluation, append_evaluation, fingerprint, read_evaluations

__all__ = ["setup_of", "bundled", "bundle"]


def setup_of(case) -> str:
    """Fingerprint of the case file ``case`` as ``drape identify --base case`` computes it (no
    ``--set``, the case's own weight)."""
    loaded = load_case(case, [])
    return fingerprint(dump_case(loaded), [], float(loaded.material.kes.weight))


def bundled(evaluation: Evaluation, setup: str, index: int) -> Evaluation:
    """``evaluation`` as the bundle keeps it, its ``index``-th: stamped ``setup``, named
    ``bNNN``, its run folders made names (``bundled/<setup>/bNNN/s<seed>``)."""
    name = f"b{index:03d}"
    runs = [{"seed": r["seed"], "status": r["status"], "run_dir": f"bundled/{setup}/{name}/s{r['seed']}",
             "wall_time_s": r.get("wall_time_s", 0.0), "reason": r.get("reason", ""), "drape": r.get("drape")}
            for r in evaluation.runs]
    return Evaluation(evaluation.point, setup, runs, name)


def bundle(libraries, case, out=None, from_setup: str | None = None) -> tuple[int, str]:
    """Append the evaluations of ``libraries`` made in the set-up of ``case`` to the bundle.

    Parameters
    ----------
    libraries : list of path
        Library folders of ``drape identify``.
    case : path
        The bundled base case the runs were made on.
    out : path, optional
        The bundle's folder (default: the package's, ``cases/libraries/identification``).
    from_setup : str, optional
        Take instead the evaluations stored under this earlier fingerprint of the same case,
        and stamp them with today's: for runs made before a change that left the forward runs
        as they were (a new case key at its default).

    Returns
    -------
    (int, str)
        How many evaluations were added (those with drapes whose point the bundle lacks), and
        the set-up's fingerprint.
    """
    out = Path(out) if out is not None else cases_dir("libraries", "identification")
    setup = setup_of(case)
    wanted = from_setup or setup
    stored = read_evaluations(out)
    have = {(e.setup, tuple(sorted(e.point.items(), key=str))) for e in stored}
    added = 0
    for library in libraries:
        for e in read_evaluations(library):
            key = (setup, tuple(sorted(e.point.items(), key=str)))
            if e.setup != wanted or key in have or not e.drapes.dc.size:
                continue
            append_evaluation(out, bundled(e, setup, len(stored) + added))
            have.add(key)
            added += 1
    return added, setup
