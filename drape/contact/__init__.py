"""Contact of the fabric with rigid bodies and with itself (Incremental Potential Contact).

The scene of fabric and bodies (:mod:`drape.contact.bodies`), the barrier and lagged friction
forces with their tangents and the collision-free step (:mod:`drape.contact.contact`), the
barrier stiffness (:mod:`drape.contact.stiffness`); the rigid surfaces and their prescribed
paths come from :mod:`drape.contact.shapes` (plane patch, sphere, cylinder, rounded box, disc,
or a mesh file) and :mod:`drape.contact.motion` (a keyframed path).
"""
from .errors import ContactInputError
from .motion import RigidPath
from .shapes import Surface, cylinder, disc, plane, read_surface, rounded_box, sphere

__all__ = ["ContactInputError", "RigidPath", "Surface", "plane", "sphere", "cylinder",
           "rounded_box", "disc", "read_surface"]
