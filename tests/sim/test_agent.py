"""Agent motion: no passing through walls or furniture, discrete actions, waypoint following."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from capnav.core.errors import InputError
from capnav.core.grid import FREE
from capnav.sim import Simulator
from capnav.sim.shapes import RectSet


def _segment_clear(sim: Simulator, a: tuple[float, float, float], b: tuple[float, float, float]) -> bool:
    pts = np.linspace([a[0], a[1]], [b[0], b[1]], 60)
    r = sim.config.agent.radius
    return bool(sim._obstacles.min_distance(pts).min() >= r - 1e-6)


def test_random_walk_never_enters_an_obstacle(small_sim: Simulator) -> None:
    rng = np.random.default_rng(0)
    x, y = small_sim.random_navigable_point(rng)
    agent = small_sim.spawn_agent(x, y, 0.0)
    blocked = 0
    for _ in range(400):
        action = ["move_forward", "move_forward", "move_forward", "turn_left", "turn_right"][int(rng.integers(5))]
        ok = agent.step(action)
        blocked += not ok
    assert blocked > 0  # the walk did run into things
    traj = agent.trajectory
    for a, b in itertools.pairwise(traj):
        assert _segment_clear(small_sim, a, b)
    moved = sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in itertools.pairwise(traj))
    assert agent.path_length == pytest.approx(moved, abs=1e-9)


def test_move_to_through_a_wall_stops_at_contact(small_sim: Simulator) -> None:
    apt = small_sim.apartment
    r = apt.plan.rooms[0]
    # a point in room 0 and a target straight across its west/east wall (outside room 0)
    grid = small_sim.nav_grid()
    pts = grid.free_points()
    inside = pts[(pts[:, 0] > r.x0 + 0.5) & (pts[:, 0] < r.x1 - 0.5) & (pts[:, 1] > r.y0) & (pts[:, 1] < r.y1)]
    start = inside[len(inside) // 2]
    agent = small_sim.spawn_agent(float(start[0]), float(start[1]))
    target = (apt.bounds[2] + 5.0, float(start[1]))  # beyond the outer wall on the east
    assert agent.move_to(*target) is False
    assert agent.x < apt.bounds[2] - small_sim.config.agent.radius + 1e-9
    assert not small_sim.collides(agent.x, agent.y)
    # it stopped at contact: 2 cm further would collide (with a wall or furniture on the way)
    assert small_sim.collides(agent.x + 0.02, agent.y)


def test_cannot_walk_into_furniture(small_sim: Simulator) -> None:
    rng = np.random.default_rng(3)
    o = max(small_sim.apartment.objects, key=lambda o: o.model.size[0] * o.model.size[1])
    fp = RectSet.from_lists([(o.x, o.y)], [o.model.size[:2]], [o.yaw])
    pts = small_sim.nav_grid().free_points()
    d = fp.min_distance(pts)
    near = pts[(d < 1.0) & (d > 0.3)]
    start = near[int(rng.integers(len(near)))]
    agent = small_sim.spawn_agent(float(start[0]), float(start[1]))
    assert agent.move_to(o.x, o.y) is False
    assert fp.min_distance(np.array([[agent.x, agent.y]]))[0] >= small_sim.config.agent.radius - 1e-6


def test_turns_and_forward_step(small_sim: Simulator) -> None:
    nav = small_sim.navigable()
    # a cell with plenty of room around it
    clear = small_sim.nav_grid().clearance * (nav.cells == FREE)
    rc = np.unravel_index(int(np.argmax(clear)), clear.shape)
    x, y = nav.spec.to_world(np.array(rc))
    agent = small_sim.spawn_agent(float(x), float(y), 0.0)
    assert agent.step("turn_left") and agent.yaw == pytest.approx(math.radians(30))
    assert agent.step("turn_right") and agent.step("turn_right")
    assert agent.yaw == pytest.approx(-math.radians(30))
    assert agent.step("move_forward")
    assert math.hypot(agent.x - x, agent.y - y) == pytest.approx(0.25)
    assert agent.path_length == pytest.approx(0.25)
    with pytest.raises(InputError):
        agent.step("jump")
    T = agent.camera_pose()
    assert T[2, 3] == pytest.approx(small_sim.config.agent.camera_height)
    f = agent.observe(index=5)
    assert f.index == 5 and f.depth.shape == (120, 160)


def test_spawn_inside_an_obstacle_is_refused(small_sim: Simulator) -> None:
    o = small_sim.apartment.objects[0]
    with pytest.raises(InputError):
        small_sim.spawn_agent(o.x, o.y)
    with pytest.raises(InputError):
        small_sim.spawn_agent(float("nan"), 1.0)


def test_navigable_cells_are_collision_free_and_connected(small_sim: Simulator) -> None:
    nav = small_sim.navigable(0.1)
    free = np.argwhere(nav.cells == FREE)
    xy = nav.spec.to_world(free)
    assert not small_sim.collides_many(xy).any()
    # every free cell is reachable from every other (single component)
    g = small_sim.nav_grid(0.1)
    node = g.snap((float(xy[0, 0]), float(xy[0, 1])), 0.0)[0]
    dist, _ = g.distance_field(node)
    assert np.isfinite(dist).all()


def test_obstacle_grid_covers_footprints_and_walls(small_sim: Simulator) -> None:
    occ = small_sim.obstacles(0.05)
    for o in small_sim.apartment.objects:
        rc = occ.spec.to_cell(np.array([o.x, o.y]))
        assert occ.cells[rc[0], rc[1]] == 1
    nav = small_sim.navigable(0.05)
    assert not np.any((occ.cells == 1) & (nav.cells == FREE))


def test_geodesic_distance(small_sim: Simulator) -> None:
    rng = np.random.default_rng(2)
    for _ in range(5):
        a, b = small_sim.random_navigable_point(rng), small_sim.random_navigable_point(rng)
        d = small_sim.geodesic_distance(a, b)
        assert math.hypot(a[0] - b[0], a[1] - b[1]) - 1e-9 <= d < 100
        path = small_sim.shortest_path(a, b)
        assert len(path) >= 1
        assert np.sum(np.hypot(*np.diff(path, axis=0).T)) == pytest.approx(d, abs=1e-6)
    assert small_sim.geodesic_distance(a, a) == 0.0
    _x0, _y0, x1, y1 = small_sim.apartment.bounds
    assert small_sim.geodesic_distance(a, (x1 + 10.0, y1 + 10.0)) == float("inf")
    with pytest.raises(InputError):
        small_sim.geodesic_distance((float("nan"), 0.0), a)
