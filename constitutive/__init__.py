"""Hysteretic bending law of fabrics, the KES-FB pure bending test and fitting.

This package knows nothing of meshes: every object here works on arrays of
material points (curvatures, curvature rates) of any shape.

Subpackages
-----------
material
    :class:`~constitutive.material.FabricMaterial`, material files, the bundled library.
datasets
    The thesis's KES-FB loops and CSV exports of an instrument.
fit
    Fitting the law to loops (``python -m constitutive.fit``).
"""

__all__: list[str] = []
