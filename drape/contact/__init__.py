"""Contact of the fabric with rigid bodies and with itself (Incremental Potential Contact).

The scene of fabric and bodies (:mod:`drape.contact.bodies`), the barrier and lagged friction
forces with their tangents and the collision-free step (:mod:`drape.contact.contact`), the
barrier stiffness (:mod:`drape.contact.stiffness`); the rigid surfaces and their prescribed
paths come from :mod:`drape.contact.shapes` and :mod:`drape.contact.motion`.
"""
