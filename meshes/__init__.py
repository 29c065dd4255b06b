"""Meshes for fabric specimens: strips, rectangles, Cusick annuli, circles and imported meshes.

Every function returns an :class:`skfem.MeshTri` in metres with named
boundaries (``mesh.boundaries[name]`` = facet indices), checked on creation
(:func:`check_mesh`; errors are :class:`MeshError`, a ``ValueError``).
"""
from .annulus import cusick_annulus
from .circle import circle
from .io import load_mesh, save_mesh
from .quality import MeshError, MeshQuality, check_mesh
from .rectangle import graded_nodes, rectangle, strip

__all__ = ["rectangle", "strip", "graded_nodes", "cusick_annulus", "circle", "load_mesh", "save_mesh", "check_mesh",
           "MeshError", "MeshQuality"]
