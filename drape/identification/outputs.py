"""What an identification leaves in DIR: the identified point run once more, ``identified.json``,
``material.toml`` and ``report.html``.

``material.toml`` holds the whole material of the point's runs, the base case's part of it
(its G, thickness, ...) included: given as the base case's ``[material] path``, it builds the
material the runs built (:mod:`drape.identification.material_file`).

The identified point is the surrogate's (:meth:`drape.identification.surrogate.Surrogate.identified`;
not the best evaluation, whose misfit carries its seeds' luck); it is run under the same seeds as every point, and its drapes are the
simulated ones the report sets beside the scans and the prediction a validation compares.
Where the search ran that very point (its stop asks for the answer run), those runs are the
final's, stored again under its name, not run twice.
"""
from __future__ import annotations

import json
import time

from drape.batch.prediction import interval, interval_line
from drape.case.build import build_material
from drape.case.case import load_case
from drape.identification.material_file import write_material
from drape.identification.objective import misfit
from drape.identification.parameters import PARAMETERS, full_point, kes_values, overrides
from drape.identification.report import simulated_measurements, write_report
from drape.identification.store import Evaluation, append_evaluation, read_evaluations
from drape.identification.surrogate import WITHIN, Surrogate

__all__ = ["FINAL", "INTERVAL_RULE", "MATCHED_Z", "finish", "material_file", "predictive_interval"]

#: ``|z_DC|`` up to which the identified point's drapes count as matching the scans' DC.
MATCHED_Z = 2.0
#: Name of the identified point's evaluation.
FINAL = "identified"
INTERVAL_RULE = (f"Intervals: the range of each parameter over the part of the box where the "
                 f"Gaussian-process surrogate's misfit, one posterior standard deviation on the "
                 f"hopeful side, is within {WITHIN:g} of its mean at the identified point (J sums squared "
                 f"differences in units of the scans' scatter between specimens, so there a "
                 f"point may match the scans as well as the best, up to that scatter).")


def _final_evaluation(search, found: dict, forward):
    """The identified point's evaluation: stored already (a resumed identification) or run."""
    point = full_point(found["answer"]["point"], search.free)
    stored = read_evaluations(search.out)
    finals = [e for e in stored if e.name.startswith(FINAL)]
    here = [e for e in stored if e.setup == search.setup and e.point == point]
    for e in here:
        if e.name.startswith(FINAL):
            return e
    # a resumed identification given more evaluations may end at another point: its own folder
    name = FINAL if not finals else f"{FINAL}-{len(finals)}"
    for e in here:
        # the search ran the answer itself (the stop asks for that): the same point under the
        # same seeds gives the same drapes, so its runs are the final's
        if len(e.drapes):
            final = Evaluation(e.point, e.setup, [{**r, "wall_time_s": 0.0} for r in e.runs], name)
            append_evaluation(search.out, final)
            return final
    t0 = time.perf_counter()
    forward.submit(name, point)
    evaluation = forward.next_finished()
    search.seconds["forward_wait"] += time.perf_counter() - t0
    append_evaluation(search.out, evaluation)
    if search.library is not None:
        append_evaluation(search.library, evaluation)
    return evaluation


def finish(search, found: dict, forward, scans, weight: float, thickness, definition) -> dict:
    """Run the identified point, write identified.json, material.toml and report.html."""
    final = _final_evaluation(search, found, forward)
    if not len(final.drapes):
        raise RuntimeError(f"the identified point's runs gave no drape (see {search.out / 'runs'})")
    t0 = time.perf_counter()
    answer = found["answer"]
    point = final.point
    m = misfit(search.target, final.drapes)
    material = material_file(search.out / "material.toml", definition, point, weight, thickness,
                             answer["intervals"], len(search.target))
    forward_cpu = sum(e.wall_time_s for e in read_evaluations(search.out))
    result = {
        "parameters": answer["point"], "intervals": answer["intervals"],
        "units": {k: PARAMETERS[k].unit for k in search.free},
        "interval_rule": INTERVAL_RULE, "fixed": {k: v for k, v in point.items()
                                                  if k not in search.free},
        "weight_mg_per_cm2": weight, "material_kes": kes_values(point, weight),
        "material_file": str(material), "target": search.target.summary(),
        "simulated": final.drapes.summary(), "misfit": dict(m), "surrogate": answer,
        # a final copied from the search's own run of the answer was not run again
        "evaluations": {"this_folder": found["own"] + int(final.wall_time_s > 0),
                        "from_library": found["library"],
                        "seeds": definition["seeds"],
                        "ended": search.converged or "the budget of evaluations was spent"},
        "seconds": {**{k: round(v, 2) for k, v in search.seconds.items()},
                    "forward_runs_worker_total": round(forward_cpu, 1)},
        "scans": [str(s) for s in definition["scans"]],
    }
    params = ", ".join(f"{k} {v:.3g} [{answer['intervals'][k]['low']:.3g}, "
                       f"{answer['intervals'][k]['high']:.3g}] {PARAMETERS[k].unit}"
                       for k, v in answer["point"].items())
    result["matched"] = bool(abs(m["z_DC"]) <= MATCHED_Z)
    warn = "" if result["matched"] else (f"NOT MATCHED (the identified point's DC is over "
                                         f"{MATCHED_Z:g} sd of the scans' scatter off), ")
    result["prediction"] = predictive_interval(found.get("evaluations", []), final, answer["intervals"])
    result["summary_line"] = (f"{warn}identified: {params}; DC {final.drapes.dc.mean():.1f} % against "
                              f"{search.target.dc.mean():.1f} %, nodes {final.drapes.nodes.tolist()}"
                              f" against {search.target.nodes.tolist()}, J = {m.J:.2f}\n"
                              f"predicted: {interval_line(result['prediction'])} (the "
                              f"{result['prediction']['drapes']} drapes of the "
                              f"{result['prediction']['points']} points run within the intervals)")
    history = found["history"] + [{"name": FINAL, "point": answer["point"], **m}]
    surrogate_for_map = _refit(search, found)
    write_report(search.out, result, scans, simulated_measurements(final), history,
                 surrogate_for_map)
    search.seconds["io"] += time.perf_counter() - t0
    result["seconds"] = {**{k: round(v, 2) for k, v in search.seconds.items()},
                         "forward_runs_worker_total": result["seconds"]["forward_runs_worker_total"]}
    (search.out / "identified.json").write_text(json.dumps(result, indent=1))
    return result


def predictive_interval(evaluations, final: Evaluation, intervals: dict) -> dict:
    """The identified fabric's predicted drape, in :func:`drape.batch.prediction.interval`'s form.

    Every drape of the points run within the identified intervals of each free parameter (the
    final point's among them): the seeds' scatter and the parameters' uncertainty together, with
    no run of its own. ``points`` and ``drapes`` count what it stands on.
    """
    def within(e) -> bool:
        return all(iv["low"] <= e.point[k] <= iv["high"] for k, iv in intervals.items())

    inside = [e for e in evaluations if e.point != final.point and within(e)]
    drapes = [d for e in [final, *inside] for d in e.drapes.drapes]
    return {**interval([d.dc for d in drapes], [d.nodes for d in drapes]),
            "points": 1 + len(inside), "drapes": len(drapes)}


def _run_case(definition: dict, point: dict, weight: float):
    """The case a run of ``point`` loads: the base case, the definition's ``--set`` items, the
    weight and the point's overrides."""
    items = list(definition["set"]) + [f"material.kes.weight={weight:g}"] + overrides(point, weight)
    return load_case(definition["base"], items)


def material_file(path, definition: dict, point: dict, weight: float, thickness,
                  intervals: dict, scans: int):
    """Write ``material.toml`` of ``point``: the whole material of its runs (the base case's
    G, thickness, ... and the definition's ``--set`` items on the material included), so that
    given as the base case's ``[material] path`` it builds what :func:`_built` builds
    (:func:`drape.identification.material_file.write_material`)."""
    run = _run_case(definition, point, weight)
    return write_material(path, "identified", point, weight, thickness, intervals, scans,
                          built=build_material(run), case=run, base=definition["base"])


def _built(definition: dict, point: dict, weight: float):
    """The material a run of ``point`` builds (SI)."""
    return build_material(_run_case(definition, point, weight))


def _refit(search, found: dict):
    """A surrogate on every evaluation, for the report's map."""
    s = Surrogate(search.box)
    for h in found["history"]:
        s.register(h["point"], h["J"])
    return s
