"""Where a run's wall time went, and how much Newton work it took.

:class:`RunProfile` adds up the integrator's step records; at the end of a run it reads the
model's own timers (``model.seconds``: the laws' trial moments and the rest of the force and
tangent evaluation) and the linear solver's (analysis, factorisation, solve, and how many
factorisations were LDLᵀ because a step matrix was not positive definite), and puts the
rest under ``other`` (Newton's vector work, step control). ``summary.json`` keeps it as
``profile``.
"""
from __future__ import annotations

__all__ = ["RunProfile"]


class RunProfile:
    """Counts of converged steps, Newton iterations, force evaluations and factorisations,
    failed attempts, steps that only a fallback start or tangent converged, and the output time.

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> p = RunProfile()
    >>> p.add(NS(iterations=3, evaluations=5, factorizations=3, cuts=1, rescued=False))
    >>> model = NS(seconds={"law": 1.0, "assembly": 2.0})
    >>> solver = NS(seconds={"analysis": 0.1, "factorization": 0.5, "solve": 0.4}, ldlt_factorizations=0)
    >>> p.summary(model, solver, wall=5.0)["seconds"]
    {'assembly': 2.0, 'law': 1.0, 'linear_solve': 1.0, 'output': 0.0, 'other': 1.0}
    """

    def __init__(self):
        self.steps = self.iterations = self.evaluations = self.factorizations = self.failed_attempts = 0
        self.rescued_steps = 0
        self.output_s = 0.0

    def add(self, info) -> None:
        """Count one converged step's :class:`drape.solvers.newmark.StepInfo`."""
        self.steps += 1
        self.iterations += int(info.iterations)
        self.evaluations += int(info.evaluations)
        self.factorizations += int(info.factorizations)
        self.failed_attempts += int(info.cuts)
        self.rescued_steps += int(info.rescued)

    def summary(self, model, solver, wall: float) -> dict:
        """Counts and the split of ``wall`` [s] into assembly, law, linear solve, output, other
        (and contact, when the model has it)."""
        seconds = {"assembly": float(model.seconds["assembly"]), "law": float(model.seconds["law"]),
                   "linear_solve": float(sum(solver.seconds.values())), "output": float(self.output_s)}
        if "contact" in model.seconds:   # barrier, friction and CCD (drape.contact)
            seconds["contact"] = float(model.seconds["contact"])
        seconds["other"] = max(0.0, float(wall) - sum(seconds.values()))
        return {"steps": self.steps, "newton_iterations": self.iterations, "evaluations": self.evaluations,
                "factorizations": self.factorizations,
                "ldlt_factorizations": int(solver.ldlt_factorizations),
                "failed_attempts": self.failed_attempts, "rescued_steps": self.rescued_steps,
                "seconds": {k: round(v, 3) for k, v in seconds.items()}}
