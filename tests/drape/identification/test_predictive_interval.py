"""An identification's predicted drape: every drape of the points run within its intervals."""
from __future__ import annotations

import numpy as np
import pytest

from drape.batch.prediction import LEVEL
from drape.identification.outputs import predictive_interval
from drape.identification.store import Evaluation
from drape.identification.target import Drape


def evaluation(c: float, drapes, name: str = "") -> Evaluation:
    point = {"bending_length": c, "hysteresis": 0.5}
    runs = [{"seed": k, "status": "settled", "run_dir": f"{name}{c}/{k}", "wall_time_s": 1.0, "reason": "",
             "drape": Drape(f"s{k}", dc, n, (0.12,)).to_json()} for k, (dc, n) in enumerate(drapes)]
    return Evaluation(point, "setup", runs, name)


def test_the_points_within_the_intervals_and_no_other_make_the_prediction():
    final = evaluation(2.0, [(60.0, 7), (62.0, 7)], "identified")
    inside = evaluation(1.8, [(55.0, 8), (57.0, 8)])
    outside = evaluation(3.0, [(90.0, 4), (91.0, 4)])
    again = evaluation(2.0, [(60.0, 7), (62.0, 7)], "e003")      # the search's own run of the answer
    p = predictive_interval([outside, inside, again, final], final,
                            {"bending_length": {"low": 1.7, "high": 2.2}})
    assert (p["points"], p["drapes"]) == (2, 4)
    dc = [60.0, 62.0, 55.0, 57.0]
    tail = 50 * (1 - LEVEL)
    assert p["DC_percent"]["median"] == pytest.approx(np.median(dc))
    assert (p["DC_percent"]["low"], p["DC_percent"]["high"]) == pytest.approx(
        tuple(np.percentile(dc, [tail, 100 - tail])))
    assert (p["nodes"]["low"], p["nodes"]["high"]) == (7, 8)


def test_alone_the_final_point_gives_its_seeds_scatter():
    final = evaluation(2.0, [(60.0, 7), (64.0, 8)], "identified")
    p = predictive_interval([], final, {"bending_length": {"low": 1.9, "high": 2.1}})
    assert (p["points"], p["drapes"]) == (1, 2)
    assert p["DC_percent"]["median"] == pytest.approx(62.0)
