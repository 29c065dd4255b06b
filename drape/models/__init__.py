"""Structural models of a fabric sheet: what the integrator sees.

Both models satisfy :class:`StructuralModel` (``evaluate``, ``commit``, ``state_dict``, ...)
and take their loads as plain functions of time (:func:`as_function`); they know the bending
law only through :class:`constitutive.sheet.SheetState` / :class:`constitutive.law.BendingState`
and nothing of case files.

Modules
-------
protocol
    :class:`StructuralModel`, :class:`Evaluation`, :func:`free_dofs`.
plate
    :class:`KirchhoffPlate`: small deflection, Morley or Argyris.
shell
    :class:`KirchhoffLoveShell`: large rotation, 3-vector Argyris.
air
    :class:`NormalDrag`: still air's quadratic drag.
loads
    Loads as functions of time.
perturbation
    :class:`FoldPerturbation`: a seeded fold imperfection of a Cusick specimen.
fields
    Output fields as point / cell data and flat scalar columns.
"""
from drape.models.air import NormalDrag
from drape.models.fields import flat_fields, split_fields
from drape.models.loads import amplitude, as_function
from drape.models.perturbation import FoldPerturbation, PerturbationError
from drape.models.plate import KirchhoffPlate, PlateInputError
from drape.models.protocol import Evaluation, StructuralModel, free_dofs
from drape.models.shell import KirchhoffLoveShell, ShellInputError

__all__ = ["StructuralModel", "Evaluation", "free_dofs", "KirchhoffPlate", "PlateInputError",
           "KirchhoffLoveShell", "ShellInputError", "NormalDrag", "as_function", "amplitude",
           "FoldPerturbation", "PerturbationError", "flat_fields", "split_fields"]
