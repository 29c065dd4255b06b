"""Finite-element plate and shell models of fabric, time integration and the case runner.

The FE layer knows the constitutive law only through its state-object interface
(``trial`` / ``commit``) from :mod:`constitutive`.

Subpackages
-----------
fem
    Argyris element, boundaries, assembly, kinematics, compiled kernels.
models
    :class:`~drape.models.KirchhoffPlate` and :class:`~drape.models.KirchhoffLoveShell`.
solvers
    Linear solvers, Newton, Newmark/HHT-α, quasi-static load stepping.
analyses
    What each test measures: Peirce, Cusick, KES, load cycles.
case
    The case file and what is built from it.
run
    One run: :func:`drape.run.run_case`.
batch
    Many runs: sweeps, seed ensembles, sensitivity studies, validation, reports.
identification
    The bending law's parameters from scanned drapes.
cli
    The command line: ``drape COMMAND`` and every tool's options.
"""

__all__: list[str] = ["__version__"]

#: The version of a source tree not installed; an installed one reports its distribution's
#: (``drape --version``). Kept equal to pyproject.toml's by tests/test_layout.py.
__version__ = "0.1.0"
