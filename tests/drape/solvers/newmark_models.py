"""The models the Newmark tests share: a linear Kirchhoff-plate cantilever with its first
period from Euler–Bernoulli, its free vibration from the deflection under its weight, and a
one-dof oscillator that fails on purpose where asked."""
import numpy as np
import scipy.sparse as sp
import skfem

from constitutive.law import BendingLaw
from constitutive.material import FabricMaterial
from drape.models.plate import KirchhoffPlate
from drape.models.protocol import Evaluation
from drape.solvers.newmark import initial_state
from drape.solvers.static import quasi_static

B, RHO, L, W = 2.0e-5, 0.2, 0.1, 0.02
OMEGA1 = 1.8751**2 / L**2 * np.sqrt(B / RHO)
PERIOD = 2 * np.pi / OMEGA1


def linear_cantilever(**kw):
    law = BendingLaw(k1=B, **kw.pop("law", {}))
    mat = FabricMaterial("test", RHO, None, law, law, twist_rigidity=B)
    mesh = skfem.MeshTri.init_tensor(np.linspace(0, L, 9), np.linspace(0, W, 2))
    mesh = mesh.with_boundaries({"left": lambda x: np.isclose(x[0], 0)})
    return KirchhoffPlate(mesh, mat, supports={"left": "clamped"}, **kw)


def released(plate):
    """Deflect under the weight, then switch the load off: free vibration from rest."""
    u0 = quasi_static(plate, [1.0]).u
    plate.load_scale = 0.0
    return initial_state(plate, u0=u0)


class Oscillator:
    """Stand-in model: m ü + c u̇ + k u + k3 u³ = 0 (one dof), optionally failing on purpose."""

    ndofs, fixed_dofs, load_scale, symmetric_tangent = 1, np.zeros(0, dtype=int), 1.0, True

    def __init__(self, k=4 * np.pi**2, c=0.0, k3=0.0, fail=None):
        self.k, self.c, self.k3, self.fail = k, c, k3, fail
        self.committed = [0.0]

    def prescribed(self, t):
        return None

    def lifting(self, t):
        return None

    def force_scale(self, t):
        return 0.0

    def forces(self, u, v, t):
        """Non-inertial force ``c v + k u + k3 u³`` and its u-derivative."""
        return self.c * v + self.k * u + self.k3 * u**3, self.k + 3 * self.k3 * u[0] ** 2

    def evaluate(self, u, v, a, t, tangent=None, weights=None):
        force, k = self.forces(u, v, t)
        if self.fail is not None and self.fail(self, t):
            force = np.full(1, np.nan)
        if tangent is None:
            return Evaluation(a.copy(), force)
        return Evaluation(a.copy(), force, sp.csr_matrix([[k]]), sp.csr_matrix([[self.c]]),
                          sp.csr_matrix([[1.0]])).weighted(weights)

    def commit(self, u, v, a):
        self.committed.append(float(u[0]))
