"""Many runs of one case: sweeps, seed ensembles, sensitivity studies, validation, reports.

Every row is an ordinary :func:`drape.run.run_case` in its own folder.

Modules
-------
sweep
    A base case over a run table or a grid of keys, on Dask; ``results.csv``.
ensemble
    Seed ensembles: DC and nodes as mean, standard deviation and histogram.
sensitivity
    One-factor-at-a-time studies and the tornado chart.
validation_set
    The validation cases simulated against their ``[measured]`` tables.
prediction
    A drape from a KES sheet with the interval its missing values and the seed leave.
report
    A self-contained ``report.html`` of a sweep or a run.

Studies built on them: ``cusick_sensitivity`` (the factors of a Cusick drape),
``fold_preference`` (drapes forced into n folds, by energy), ``matched_dc`` (a scanned fabric's
B matched to its DC, the node counts compared), ``outline_anisotropy`` (its warp/weft ratio read
from its outlines' elliptic harmonic, the node counts at it), ``fold_law`` (the node count over the bending
length against the fold-number law of Cerda, Mahadevan & Pasini) and ``peirce_grip`` (the Peirce platform's grip at
rest).
"""
from drape.batch.ensemble import ensemble_stats, ensembles, seed_rows
from drape.batch.prediction import describe_prediction, missing_unknowns, sample_rows, summarise
from drape.batch.report import write_report
from drape.batch.rows import SweepError, SweepRow, read_results
from drape.batch.sensitivity import Factor, Level, run_study
from drape.batch.sweep import run_sweep
from drape.batch.validation_set import run_validation, validation_cases

__all__ = ["SweepRow", "SweepError", "run_sweep", "read_results", "seed_rows", "ensembles",
           "ensemble_stats", "Factor", "Level", "run_study", "run_validation", "validation_cases",
           "write_report", "missing_unknowns", "sample_rows", "summarise", "describe_prediction"]
