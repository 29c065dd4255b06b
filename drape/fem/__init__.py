"""Finite-element building blocks shared by the plate and the shell.

The Argyris triangle with element-local scaled monomials, the dofs of named boundaries, the
fixed sparsity pattern and batched (element, quadrature point) contractions, the
Kirchhoff–Love kinematics and the shell's compiled element kernels. Nothing here knows a
material law, a load or a case file.

Modules
-------
argyris
    :class:`ElementTriArgyrisLocal` and :func:`interpolate`.
boundary
    Clamped / simply supported / free boundaries, node frames, imposed rotations.
assembly
    :class:`SparsityPattern` and the (element, qp) contractions.
kinematics
    Kirchhoff–Love kinematics and their variations (vectorised reference).
shell_kernels
    Compiled (numba) strain, curvature, internal force and step matrix of the shell.
compiled
    :func:`njit`: numba's compiler with its on-disk cache.
"""
from drape.fem.argyris import ElementTriArgyrisLocal, interpolate
from drape.fem.assembly import SparsityPattern
from drape.fem.boundary import (
                                argyris_element,
                                boundary_dofs,
                                clamped_dofs,
                                plate_constraints,
                                pure_bending_rotations,
)
from drape.fem.compiled import njit

__all__ = ["ElementTriArgyrisLocal", "interpolate", "SparsityPattern", "argyris_element",
           "boundary_dofs", "clamped_dofs", "plate_constraints", "pure_bending_rotations", "njit"]
