"""The shell's contact: a force and tangent term of ``evaluate``, a step cap, state at commit.

A part of :class:`drape.models.shell.KirchhoffLoveShell`. The contact object
(:class:`drape.contact.contact.Contact`) is attached after the shell is built
(:meth:`ShellContact.attach_contact`); without one every method here is a no-op and
``evaluate`` is exactly the contact-free one.
"""
from __future__ import annotations

import time

import numpy as np

from drape.fem.subdivision import interpolation_matrix, subdivide
from drape.models.protocol import Evaluation

__all__ = ["ShellContact"]


class ShellContact:
    """Contact terms of :class:`~drape.models.shell.KirchhoffLoveShell`."""

    contact = None

    def contact_vertices(self, subdivision: int = 1):
        """The fabric's collision vertices: reference points (n, 3), triangles (m, 3) and how
        each vertex's displacement follows from the dofs.

        With ``subdivision = 1`` the vertices are the mesh's and the third item is the dofs
        (n, 3) of each vertex's displacement (its Argyris value dofs). With ``subdivision = s
        > 1`` every triangle is split into s² sub-triangles (:mod:`drape.fem.subdivision`) and
        the third item is the sparse (3 n, ndofs) matrix ``P`` that evaluates the shell's
        field at the sub-vertices with the element basis, so that contact sees the curved
        elements rather than their chords.
        """
        s = int(subdivision)
        if s == 1:
            points = np.column_stack([self.mesh.p.T, np.zeros(self.mesh.p.shape[1])])
            dofs = 3 * np.asarray(self.basis.nodal_dofs[0])[:, None] + np.arange(3)
            return points, self.mesh.t.T, dofs
        flat, triangles, owner = subdivide(self.mesh, s)
        P = interpolation_matrix(self.mesh, self.element, owner, s)
        return np.column_stack([flat, np.zeros(len(flat))]), triangles, P

    def attach_contact(self, contact) -> None:
        """Let ``contact`` (a :class:`drape.contact.contact.Contact` on :meth:`contact_vertices`)
        act on this shell."""
        self.contact = contact
        self.seconds.setdefault("contact", 0.0)   # the contact's share of the run's time

    def _add_contact(self, ev: Evaluation, u, v, t, tangent, weights) -> Evaluation:
        """``ev`` with the contact force, and its tangent in ``J`` or in ``K`` and ``C``."""
        start = time.perf_counter()
        try:
            return self._contact_terms(ev, u, v, t, tangent, weights)
        finally:
            self.seconds["contact"] += time.perf_counter() - start

    def _contact_terms(self, ev, u, v, t, tangent, weights) -> Evaluation:
        if tangent is None:
            force, _ = self.contact.forces(u, v, t)
            return Evaluation(ev.inertia, ev.force + force)
        if weights is not None:
            force, block = self.contact.forces(u, v, t, (weights[0], weights[1]))
            return Evaluation(ev.inertia, ev.force + force, J=self.contact.add_tangent(ev.J, block))
        force, k_block, c_block = self.contact.stiffness_and_damping(u, v, t)
        return Evaluation(ev.inertia, ev.force + force, self.contact.add_tangent(ev.K, k_block),
                          self.contact.add_tangent(ev.C, c_block), ev.M)

    @property
    def max_step(self):
        """``max_step(u0, u1, t, t0=None)``: the safe fraction in (0, 1] of the step from ``u0``
        to ``u1`` by continuous collision detection
        (:meth:`drape.contact.contact.Contact.max_step`); None without contact, so that the
        step problems, for which the method is optional, do not build fields to cap nothing."""
        return None if self.contact is None else self._max_step

    def _max_step(self, u0, u1, t, t0=None) -> float:
        start = time.perf_counter()
        cap = self.contact.max_step(u0, u1, t, t0)
        self.seconds["contact"] += time.perf_counter() - start
        return cap

    def _commit_contact(self, u, v) -> None:
        if self.contact is not None:
            self.contact.commit(u, v, self._t_last)

    def _contact_state(self) -> dict:
        return {} if self.contact is None else self.contact.state_dict()

    def _load_contact_state(self, state) -> None:
        if self.contact is not None:
            self.contact.load_state_dict(state)

    def _contact_energies(self, u) -> dict:
        """The barrier's potential and the friction work [J] (empty without contact)."""
        if self.contact is None:
            return {}
        return {"contact_potential": self.contact.energy(u, self._t_last),
                "contact_friction_work": self.contact.friction_work}
