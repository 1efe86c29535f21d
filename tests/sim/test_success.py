"""Success regions and the geodesic shortest path used by SPL."""

from __future__ import annotations

import numpy as np
import pytest

from capnav.core.footprint import footprint_distance
from capnav.core.grid import GridSpec
from capnav.sim.geodesic import distance_field
from capnav.sim.success import distance_to_instances, is_success

SQUARE = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]])


def test_footprint_distance_hand_computed() -> None:
    pts = np.array([[1.0, 0.5], [3.0, 0.5], [1.0, -2.0], [3.0, 2.0], [2.0, 1.0]])
    d = footprint_distance(pts, SQUARE)
    np.testing.assert_allclose(d, [0.0, 1.0, 2.0, np.sqrt(2.0), 0.0])


def test_rotated_footprint() -> None:
    diamond = np.array([[0.0, -1.0], [1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])
    d = footprint_distance(np.array([[0.0, 0.0], [1.0, 1.0]]), diamond)
    np.testing.assert_allclose(d, [0.0, np.sqrt(0.5)])


def test_is_success_any_instance() -> None:
    other = SQUARE + np.array([10.0, 0.0])
    assert is_success((3.0, 0.5), [SQUARE, other])  # 1.0 m: on the boundary counts
    assert not is_success((5.0, 0.5), [SQUARE, other])
    assert is_success((9.2, 0.5), [SQUARE, other])
    assert distance_to_instances((0, 0), []) == float("inf")


def test_geodesic_goes_around_a_wall() -> None:
    # 10 m x 10 m room at 0.1 m; a wall at x in [4.9, 5.1) from y = 0 to 8 m; goal footprint at x ~ 8.
    spec = GridSpec(0.0, 0.0, 0.1, 100, 100)
    free = np.ones((100, 100), dtype=bool)
    free[:80, 49:51] = False
    goal = np.array([[8.0, 1.0], [8.2, 1.0], [8.2, 1.2], [8.0, 1.2]])
    field = distance_field(spec, free, [goal], radius=1.0)
    # Straight line would be ~ 6 m (from x=1 to x=7); the path must pass above the wall (y > 8 m).
    d = field.at((1.05, 1.05))
    assert d > 2 * 6.9  # up ~7 m, across, and down again
    assert d < 6.9 + 5.0 + 7.9
    # Starting inside the region: zero.
    assert field.at((7.55, 1.05)) == pytest.approx(0.0)
    # Straight open line: close to Euclidean (grid paths are at most ~8% longer).
    d_open = field.at((5.05, 9.05))
    eu = np.hypot(8.0 - 5.05, 9.05 - 1.2) - 1.0
    assert eu <= d_open + 0.15 and d_open <= 1.1 * eu + 0.2


def test_unreachable_and_blocked_start() -> None:
    spec = GridSpec(0.0, 0.0, 0.1, 20, 40)
    free = np.ones((20, 40), dtype=bool)
    free[:, 19:21] = False  # a full wall splits the room
    goal = np.array([[3.5, 1.0], [3.6, 1.0], [3.6, 1.1], [3.5, 1.1]])
    field = distance_field(spec, free, [goal], radius=0.5)
    assert np.isinf(field.at((0.5, 1.0)))
    # stopping inside the wall snaps to the nearest free cell (x = 2.15, goal side): 0.1 m + 0.9 m
    assert field.at((2.05, 1.05)) == pytest.approx(1.0, abs=1e-6)
    assert field.at((3.55, 1.05)) == 0.0

