"""Identification: the bending law's parameters from scanned Cusick drapes.

``python -m drape.identify SCANS... --base CASE --out DIR`` (:mod:`drape.cli.identify`) runs
:func:`~drape.identification.identify.identify`: the scans' descriptors
(:mod:`~drape.identification.target`), a misfit in the scans' own scatter
(:mod:`~drape.identification.objective`), forward runs as seed ensembles on Dask
(:mod:`~drape.identification.forward`) kept as they finish (:mod:`~drape.identification.store`),
Bayesian optimisation with a Gaussian-process surrogate (:mod:`~drape.identification.surrogate`,
:mod:`~drape.identification.search`), and the outputs (:mod:`~drape.identification.outputs`,
:mod:`~drape.identification.material_file`, :mod:`~drape.identification.report`).

The identification checked and fed: fabrics identified from half their specimens and judged on
the other half (:mod:`~drape.identification.specimen_split`,
:mod:`~drape.identification.held_out`), the convergence stop replayed on finished searches
(:mod:`~drape.identification.stop_replay`), and the forward runs bundled with the package
(:mod:`~drape.identification.bundle`).
"""
