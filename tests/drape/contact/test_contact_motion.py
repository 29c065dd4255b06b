"""A rigid body's keyframed path: positions between and beyond keyframes, velocities as the
derivative of the positions, bad paths refused."""
import numpy as np
import pytest

from drape.contact import ContactInputError, RigidPath

TIMES = [0.5, 1.5, 2.0]
MOVES = [[0, 0, 0], [0.1, 0, -0.2], [0.1, 0.05, -0.2]]


def test_offset_is_linear_between_keyframes_and_held_outside():
    path = RigidPath(TIMES, MOVES)
    assert np.allclose(path.offset(1.0), [0.05, 0, -0.1])
    assert np.allclose(path.offset(1.75), [0.1, 0.025, -0.2])
    assert np.allclose(path.offset(0.0), MOVES[0]) and np.allclose(path.offset(9.0), MOVES[-1])
    for t, x in zip(TIMES, MOVES):
        assert np.allclose(path.offset(t), x)
    assert path.moves and not RigidPath.still().moves


@pytest.mark.parametrize("t", [0.2, 0.7, 1.2, 1.6, 1.99, 2.4])
def test_velocity_is_the_derivative_of_the_offset(t):
    path, h = RigidPath(TIMES, MOVES), 1e-6
    central = (path.offset(t + h) - path.offset(t - h)) / (2 * h)
    assert np.allclose(path.velocity(t), central, atol=1e-6)


def test_velocity_at_a_keyframe_is_the_interval_that_ends_there():
    path = RigidPath(TIMES, MOVES)
    assert np.allclose(path.velocity(1.5), [0.1, 0, -0.2])      # the step ending at 1.5 moved so
    assert np.allclose(path.velocity(2.0), [0, 0.1, 0])
    assert np.allclose(path.velocity(0.5), 0) and np.allclose(path.velocity(2.0 + 1e-12), 0)


def test_still_path():
    still = RigidPath.still()
    for t in (-1.0, 0.0, 3.0):
        assert np.array_equal(still.offset(t), np.zeros(3))
        assert np.array_equal(still.velocity(t), np.zeros(3))


@pytest.mark.parametrize("times, moves, rule", [
    ([0, 1], [[0, 0, 0]], "rows of 3"),
    ([0, 1], [[0, 0], [1, 1]], "rows of 3"),
    ([1, 1], [[0, 0, 0], [1, 0, 0]], "strictly increasing"),
    ([0, np.nan], [[0, 0, 0], [1, 0, 0]], "finite"),
    ([], [], "at least one"),
])
def test_bad_paths_refused_in_one_line(times, moves, rule):
    with pytest.raises(ContactInputError, match=rule) as error:
        RigidPath(times, moves)
    assert "\n" not in str(error.value)
