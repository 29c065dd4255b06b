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
from drape.solvers.newmark import (
           ConvergenceError,
           IntegratorInputError,
           NewmarkState,
           initial_state,
           newmark_step,
)
from drape.solvers.newton import NewtonPolicy, NewtonResult, NewtonTolerances, NonlinearProblem, newton
from drape.solvers.static import quasi_static
from drape.solvers.step_control import StepControl
from drape.solvers.time_stepping import integrate

__all__ = ["DirectSolver", "FreeRestriction", "LinearSolverError", "pardiso_available",
           "NonlinearProblem", "NewtonTolerances", "NewtonPolicy", "NewtonResult", "newton",
           "NewmarkState", "StepControl", "ConvergenceError", "IntegratorInputError",
           "initial_state", "newmark_step", "integrate", "quasi_static"]
