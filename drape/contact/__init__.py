"""Rigid bodies the fabric touches: their triangulated surfaces and prescribed motions.

:mod:`~drape.contact.shapes` builds the surfaces (plane patch, sphere, cylinder, rounded box,
disc, or a mesh file), :mod:`~drape.contact.motion` moves them along a keyframed path.
"""
from .errors import ContactInputError
from .motion import RigidPath
from .shapes import Surface, cylinder, disc, plane, read_surface, rounded_box, sphere

__all__ = ["ContactInputError", "RigidPath", "Surface", "plane", "sphere", "cylinder",
           "rounded_box", "disc", "read_surface"]
