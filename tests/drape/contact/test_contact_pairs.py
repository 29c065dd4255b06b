"""Which contact pairs push: IPC's own set against one pair per fabric point (``pairs``).

The reference is the barrier of a single pair at the point's distance to the body
(``ipctk.barrier_force_magnitude``, the potential's derivative), which is what a point resting
on, or passing over, a rigid body should feel whatever the body's triangulation.
"""
import ipctk
import numpy as np
import pytest

from drape.contact.bodies import BACKSTOP_WEIGHT, ContactInputError, HalfSpace, RigidBody, Scene
from drape.contact.contact import Contact
from drape.contact.shapes import plane, rounded_box

DHAT, DMIN, KAPPA = 1e-5, 1e-4, 1.0


def patch(n, size, height, shift=(0.0, 0.0)):
    """A flat square of (n + 1)² points at ``height``, ``size`` wide, centred on ``shift``."""
    s = np.linspace(-size / 2, size / 2, n + 1)
    x, y = np.meshgrid(s + shift[0], s + shift[1])
    points = np.column_stack([x.ravel(), y.ravel(), np.full(x.size, height)])
    k = np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]
    a = k.ravel()
    triangles = np.vstack([np.column_stack([a, a + 1, a + n + 2]), np.column_stack([a, a + n + 2, a + n + 1])])
    return points, triangles


def contact_of(points, triangles, bodies, pairs):
    """A :class:`Contact` whose dofs are the points' displacements."""
    n = len(points)
    scene = Scene(points, triangles, bodies, pairs=pairs)
    return Contact(scene, np.arange(3 * n).reshape(n, 3), 3 * n, dhat=DHAT, stiffness=KAPPA, thickness=2 * DMIN)


def one_pair(distance):
    """The push [N] of one pair at ``distance`` from a body."""
    return abs(ipctk.barrier_force_magnitude(distance ** 2, ipctk.ClampedLogBarrier(), DHAT, KAPPA, DMIN))


def interior_push(contact, n):
    """The z force the bodies exert on the patch's interior points, per point."""
    force = -contact.forces(np.zeros(contact.ndofs), np.zeros(contact.ndofs), 0.0)[0].reshape(-1, 3)
    inner = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)[1:-1, 1:-1].ravel()
    return force[inner, 2]


def test_a_point_resting_on_a_triangulated_plate_is_pushed_once_wherever_it_lies():
    """A fine patch (0.1 mm) hovering at one height over a coarse plate (5 mm cells, its grid
    lines not the patch's): with one pair per point every interior point is pushed as one
    pair at that distance pushes; IPC's own pairs push one to five times as hard, with where
    the point lies over the plate's triangles."""
    height = DMIN + 0.5 * DHAT
    points, triangles = patch(20, 2e-3, height, shift=(0.13e-3, 0.07e-3))
    plate = RigidBody("plate", plane([0, 0, 0], [0, 0, 1], 2e-2, resolution=4))
    expected = one_pair(height)
    per_point = interior_push(contact_of(points, triangles, [plate], "per_point"), 20)
    np.testing.assert_allclose(per_point, expected, rtol=1e-9)
    ipc = interior_push(contact_of(points, triangles, [plate], "ipc"), 20)   # for contrast
    assert ipc.min() >= expected * (1 - 1e-9) and ipc.max() > 2.5 * expected


def test_a_plane_pushes_each_point_once_with_either_set():
    """A half-space's plane–vertex pairs are one per point already: ``per_point`` must weigh
    them as ``ipc`` does (ipctk weighs them by the vertex's whole area)."""
    height = DMIN + 0.3 * DHAT
    points, triangles = patch(6, 1e-3, height)
    floor = [HalfSpace("floor", [0, 0, 0], [0, 0, 1])]
    for pairs in ("ipc", "per_point"):
        np.testing.assert_allclose(interior_push(contact_of(points, triangles, floor, pairs), 6),
                                   one_pair(height), rtol=1e-9)


def barrier(distance):
    """The energy [J] of one pair at ``distance``."""
    return KAPPA * float(ipctk.ClampedLogBarrier()(distance ** 2 - DMIN ** 2, 2 * DMIN * DHAT + DHAT ** 2))


def edge_sweep(pairs, offsets, height):
    """The barrier energy of a flat patch (0.01 mm cells) at ``height`` over a box's top face,
    slid across the box's front edge (x = 0) by ``offsets``, and the energy its points would
    have with one pair each at their distance to the box (the top face, or the edge beyond it)."""
    box = RigidBody("box", rounded_box([-5e-3, 0, -5e-3], [1e-2, 1e-2, 1e-2], resolution=4))
    energies, reference = [], []
    for dx in offsets:
        points, triangles = patch(4, 4e-5, height, shift=(dx, 0.0))
        contact = contact_of(points, triangles, [box], pairs)
        energies.append(contact.energy(np.zeros(contact.ndofs), 0.0))
        distance = np.where(points[:, 0] <= 0.0, height, np.hypot(points[:, 0], height))
        reference.append(sum(barrier(d) for d in distance if d < DMIN + DHAT))
    return np.array(energies), np.array(reference)


def test_a_patch_slid_over_a_convex_edge_is_pushed_by_its_points_distances(monkeypatch):
    """Slid over a box's edge at a constant height, a patch's energy with one pair per point
    is its points' single pairs at their distances to the box, which fall smoothly past the
    edge; with the edge's backstop (its edge–edge pairs at a tenth of a pair) within a tenth of that.
    IPC's pairs count points near the edge several times over: a hump as steep as the
    barrier, which the patch has to climb."""
    height = DMIN + 0.5 * DHAT
    offsets = np.linspace(-6e-5, 2e-5, 41)
    with monkeypatch.context() as m:
        m.setattr("drape.contact.bodies.BACKSTOP_WEIGHT", 0.0)
        alone, reference = edge_sweep("per_point", offsets, height)
    np.testing.assert_allclose(alone, reference, rtol=1e-9)
    backed, _ = edge_sweep("per_point", offsets, height)
    assert np.all(np.abs(backed / reference - 1.0) <= BACKSTOP_WEIGHT)
    ipc, _ = edge_sweep("ipc", offsets, height)
    assert np.max(ipc / reference) > 2.0


def test_pairs_other_than_the_two_sets_are_refused():
    points, triangles = patch(1, 1e-3, 1.0)
    with pytest.raises(ContactInputError, match="contact.pairs"):
        Scene(points, triangles, [], pairs="closest")
