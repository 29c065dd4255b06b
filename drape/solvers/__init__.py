"""Solving a structural model: linear systems, Newton, Newmark/HHT-α time stepping.

The solvers see a model only through :class:`drape.models.StructuralModel`.

Modules
-------
linear
    :class:`DirectSolver` (PARDISO or SuperLU), :class:`FreeRestriction`.
newton
    :func:`newton`: error-oriented damped Newton on a :class:`NonlinearProblem`.
newmark
    :func:`integrate`, :func:`newmark_step`, :func:`quasi_static`.
"""
from drape.solvers.linear import DirectSolver, FreeRestriction, LinearSolverError, pardiso_available
from drape.solvers.newmark import (ConvergenceError, IntegratorInputError, NewmarkState, StepControl,
                                   initial_state, integrate, newmark_step, quasi_static)
from drape.solvers.newton import NewtonPolicy, NewtonResult, NewtonTolerances, NonlinearProblem, newton

__all__ = ["DirectSolver", "FreeRestriction", "LinearSolverError", "pardiso_available",
           "NonlinearProblem", "NewtonTolerances", "NewtonPolicy", "NewtonResult", "newton",
           "NewmarkState", "StepControl", "ConvergenceError", "IntegratorInputError",
           "initial_state", "newmark_step", "integrate", "quasi_static"]
