"""Hysteretic bending law of fabrics, the KES-FB pure bending test and fitting.

This package knows nothing of meshes: every object here works on arrays of
material points (curvatures, curvature rates) of any shape.
"""
