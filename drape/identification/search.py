"""The identification loop: design, out-of-reach check, Bayesian optimisation, stored as it goes.

1. The stored evaluations of this folder (a resumed identification) and those of a library in
   the same set-up (the user's, and the forward runs bundled with the package, read only) are
   scored against the scans and registered with the surrogate.
2. The initial design (:func:`drape.identification.surrogate.design`: the box's two corners,
   then Latin-hypercube points) is run where it is not already known.
3. Once both corners are known, a scan set whose mean DC lies beyond what the corners reach
   (the drape coefficient grows with the bending length and the hysteresis) by more than the
   scans' own scatter is out of the model's reach over the box: :class:`OutOfReach`, instead of
   an answer at the nearest corner.
4. The surrogate suggests the remaining points, ``in_flight`` at a time, until the budget of
   evaluations is spent, or until it asks for a point within ``converged_within`` (in widths
   of the box, log scale) of one already run or running while its answer (the point it would
   report, :meth:`~drape.identification.surrogate.Surrogate.identified`) lies that close to a
   point run: the search has converged. Near its best the misfit is flat within the drapes'
   own seed scatter, and a surrogate that has seen that proposes the same point again and
   again (creeping by a fraction of a percent), each time for a full forward ensemble that
   adds next to nothing. But the acquisition may come back to a point it knows while the
   answer lies where nothing was run (between library points made for other fabrics), and
   there the surrogate can be wrong by more than the scans' scatter: such an answer is run
   next, as an ordinary evaluation, before the search may end.

Every finished evaluation is appended to the folder's store (and the library's) at once; the
points in flight are in ``pending.json``, submitted again first on ``--resume`` (their runs
continue from their checkpoints).
"""
from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

from drape.identification.objective import misfit
from drape.identification.parameters import full_point
from drape.identification.store import Evaluation, append_evaluation, library_evaluations, read_evaluations
from drape.identification.surrogate import Surrogate, design, unit_distance
from drape.run.atomic import atomic_write_text

__all__ = ["OutOfReach", "Search", "run_search", "CONVERGED_WITHIN"]

PENDING = "pending.json"
#: A suggested point this close to one run (largest difference of a parameter, in widths of the
#: box on its log scale) ends the search. A hundredth of the bending-length box 0.6-3 cm is
#: 1.6 % of c, about one point of DC at mid DC, half the seed scatter of a point's mean DC.
CONVERGED_WITHIN = 0.01


class OutOfReach(ValueError):
    """The scans' drape coefficient is beyond what the model reaches over the box."""


@dataclass
class Search:
    """What one identification runs (see :func:`run_search`)."""

    target: object                   # Drapes of the scans
    box: dict
    evaluations: int                 # budget of new evaluations in this folder
    out: Path
    setup: str
    library: Path | None = None
    n_design: int | None = None
    bundled: Path | None = None      # forward runs shipped with the package: read, never written
    converged_within: float = CONVERGED_WITHIN   # 0: spend the whole budget
    converged: str = ""                          # why the search ended early, if it did
    seconds: dict = field(default_factory=lambda: {"forward_wait": 0.0, "surrogate": 0.0,
                                                   "io": 0.0})

    @property
    def free(self) -> list[str]:
        return list(self.box)

    def design_size(self) -> int:
        return self.n_design if self.n_design is not None else 2 * len(self.box)


def _same(a: dict, b: dict, names) -> bool:
    return all(math.isclose(a[k], b[k], rel_tol=1e-5) for k in names)


def _check_reach(search: Search, known: list[Evaluation]) -> None:
    """Raise :class:`OutOfReach` when the scans' mean DC is beyond the corners' by more than
    their scatter (nothing to say until both corners are known)."""
    low, high = design(search.box, 0)
    at = {}
    for side, corner in (("low", low), ("high", high)):
        found = [e for e in known if _same(e.point, corner, search.free) and len(e.drapes)]
        if not found:
            return
        at[side] = (corner, float(found[0].drapes.dc.mean()))
    dc = float(search.target.dc.mean())
    s = max(search.target.dc_std(), 1.0)
    for side, beyond in (("high", dc > at["high"][1] + s), ("low", dc < at["low"][1] - s)):
        if beyond:
            corner, reach = at[side]
            where = ", ".join(f"{k} = {v:g}" for k, v in corner.items())
            word = "above" if side == "high" else "below"
            raise OutOfReach(
                f"the scans' mean DC {dc:.1f} % is {word} what the model reaches over the box "
                f"({reach:.1f} % at {where}, the {side} corner; the scans' scatter {s:.1f} points): "
                f"out of the model's reach; widen --box or check the scans")


def _is_corner(search: Search, point: dict) -> bool:
    return any(_same(point, c, search.free) for c in design(search.box, 0))


def _corners_known(search: Search, known: list[Evaluation]) -> bool:
    return all(any(_same(e.point, c, search.free) for e in known) for c in design(search.box, 0))


def _nearby(search: Search, point: dict, known: list[Evaluation], pending: dict) -> tuple | None:
    """``(distance, name)`` of the point run (``known``) or running (``pending``) nearest to
    ``point``, if it lies within ``converged_within``; else None."""
    if search.converged_within <= 0:
        return None
    others = [(e.name, e.point) for e in known] + [(name, v[0]) for name, v in pending.items()]
    if not others:
        return None
    d, name = min((unit_distance(search.box, point, q), n) for n, q in others)
    return (d, name) if d <= search.converged_within else None


def _next_point(search: Search, surrogate: Surrogate, known: list[Evaluation], pending: dict):
    """The point to run next: the surrogate's suggestion, or its answer where the suggestion
    comes back to a point it has and the answer has not been run. None when there is nothing
    to run: the search has converged (``search.converged`` says why), or its answer is running."""
    free = search.free
    point = full_point(surrogate.suggest(), free)
    near = _nearby(search, point, known, pending)
    if near is None:
        return point
    surrogate.withdraw()
    answer = full_point(surrogate.identified()["point"], free)
    if _nearby(search, answer, known, {}) is not None:
        d, name = near
        search.converged = (f"converged: the surrogate's next point lies within {d:.4f} box "
                            f"widths of {name}, and its answer by one run "
                            f"(converged_within {search.converged_within:g})")
        return None
    if _nearby(search, answer, [], pending) is not None:
        return None
    return answer


def _registered(surrogate: Surrogate, search: Search, evaluations) -> list[dict]:
    """Register the evaluations with a drape; return their history rows."""
    rows = []
    for e in evaluations:
        if not len(e.drapes):
            continue
        m = misfit(search.target, e.drapes)
        surrogate.register({k: e.point[k] for k in search.free}, m.J)
        rows.append({"name": e.name, "point": {k: e.point[k] for k in search.free}, **m,
                     "DC_mean_percent": float(e.drapes.dc.mean()),
                     "nodes": e.drapes.nodes.tolist()})
    return rows


def _write_pending(out: Path, pending: dict) -> None:
    atomic_write_text(out / PENDING, json.dumps({k: v[0] for k, v in pending.items()}))


def run_search(search: Search, forward, in_flight: int = 1, progress=None) -> dict:
    """Run the identification; return its history and the surrogate's answer.

    Parameters
    ----------
    search : Search
    forward : drape.identification.forward.ForwardRuns
    in_flight : int
        Points evaluated at once.
    progress : tqdm, optional
        Advanced once per finished evaluation.

    Raises
    ------
    OutOfReach
    """
    out, free = search.out, search.free
    t0 = time.perf_counter()
    own = read_evaluations(out)
    lib = []
    fixed = {k: v for k, v in full_point({k: 0.0 for k in free}, free).items() if k not in free}
    names = {e.runs[0]["run_dir"] for e in own if e.runs}
    for folder in (search.library, search.bundled):
        if folder is None:
            continue
        for e in library_evaluations(folder, search.setup, fixed):
            if e.runs and e.runs[0]["run_dir"] not in names:
                lib.append(e)
                names.add(e.runs[0]["run_dir"])
    search.seconds["io"] += time.perf_counter() - t0

    t0 = time.perf_counter()
    surrogate = Surrogate(search.box)
    history = _registered(surrogate, search, lib + own)
    search.seconds["surrogate"] += time.perf_counter() - t0
    known = lib + own
    _check_reach(search, known)

    pending_file = out / PENDING
    resubmit = json.loads(pending_file.read_text()) if pending_file.exists() else {}
    queue = [(name, point) for name, point in resubmit.items()]
    queue += [(None, full_point(p, free)) for p in design(search.box, search.design_size())
              if not any(_same(e.point, p, free) for e in known)
              and not any(_same(q, p, free) for _, q in queue)]
    queue.sort(key=lambda item: not _is_corner(search, item[1]))     # the reach first
    done = sum(1 for e in own if not e.name.startswith("identified"))   # the final ones aside
    index = len(own) + len(resubmit)
    if progress is not None:
        progress.reset(total=search.evaluations)
        progress.update(done)
    try:
        while (done < search.evaluations and not search.converged) or forward.pending:
            while (done + len(forward.pending) < search.evaluations and len(forward.pending) < in_flight
                   and not search.converged):
                if not _corners_known(search, known) and not (queue and _is_corner(search, queue[0][1])):
                    break       # nothing else runs before the reach is known
                if queue:
                    name, point = queue.pop(0)
                else:
                    t0 = time.perf_counter()
                    point = _next_point(search, surrogate, known, forward.pending)
                    search.seconds["surrogate"] += time.perf_counter() - t0
                    if point is None:
                        break
                    name = None
                if name is None:
                    name, index = f"e{index:03d}", index + 1
                forward.submit(name, point)
                _write_pending(out, forward.pending)
            if not forward.pending:
                break
            t0 = time.perf_counter()
            evaluation = forward.next_finished()
            search.seconds["forward_wait"] += time.perf_counter() - t0
            t0 = time.perf_counter()
            append_evaluation(out, evaluation)
            if search.library is not None:
                append_evaluation(search.library, evaluation)
            _write_pending(out, forward.pending)
            search.seconds["io"] += time.perf_counter() - t0
            t0 = time.perf_counter()
            history += _registered(surrogate, search, [evaluation])
            search.seconds["surrogate"] += time.perf_counter() - t0
            known.append(evaluation)
            done += 1
            if progress is not None:
                progress.update(1)
            _check_reach(search, known)
    finally:
        forward.cancel()
    if not history:
        raise OutOfReach("no forward run gave a drape: nothing to identify from "
                         "(see the runs' run.log under DIR/runs)")
    t0 = time.perf_counter()
    answer = surrogate.identified()
    search.seconds["surrogate"] += time.perf_counter() - t0
    return {"history": history, "answer": answer, "evaluations": known,
            "own": done, "library": len(lib)}
