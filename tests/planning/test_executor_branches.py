"""The executor's answers when the world is tighter than the map in a way a contact cannot teach:
a goal it cannot stand on is refused and another chosen; the same contact twice ends the drive
with the reason; a goal walled off on the map (a closed door) is said to be cut off, not silently
missed. Worlds of boxes (``test_tight_reach.BoxWorld``), the map a few centimetres off."""

from __future__ import annotations

import numpy as np
from test_tight_reach import BoxWorld, dist, grid_of, square

from capnav.core.grid import FREE, OCCUPIED, GridSpec, OccupancyGrid
from capnav.planning import navigate_to, select_goal
from capnav.sim.agent import Agent


def test_a_goal_the_world_does_not_let_it_stand_on_is_refused_and_another_reached() -> None:
    # A sideboard the world has 7-13 cm deeper than the map; the object (a lamp) stands just north
    # of it. The first goal, at the sideboard's west corner, lies where the world's sideboard is:
    # the agent stops 6 cm short, against an obstacle the map already holds (nothing new to mark).
    bounds = (0.0, 0.0, 4.0, 3.0)
    world = BoxWorld([(2.57, 1.54, 3.93, 2.5)], bounds)
    fp = square(3.2, 2.66, 0.1)
    agent = Agent(world, 0.3, 2.35)
    res = navigate_to(agent, grid_of([(2.64, 1.61, 3.92, 2.37)], bounds), fp)
    refusals = [e for e in res.events if "goals where it stands refused" in e]
    assert len(refusals) == 1, res.events
    assert "already on the map" in refusals[0]
    first, last = res.plans[0].waypoints[-1], res.plans[-1].waypoints[-1]
    # the goal after the refusal is off the refused disk (the robot's radius around where it stood)
    assert float(np.linalg.norm(last - first)) > 0.2
    assert res.reached and dist(agent, fp) <= 1.0, (res.reason, res.events)
    assert res.replans <= 3 and "gave up" not in res.reason


def test_the_same_contact_twice_ends_the_drive_with_the_reason() -> None:
    # A corridor under a counter 0.41 m wide in the world (1 cm of slack for the 0.4 m robot),
    # 0.59 m on the map; the object on the counter. The agent creeps along the corridor, is
    # stopped where the world's counter is, refuses that goal and is stopped at the same contact
    # again: it ends there, saying so, instead of replanning the same plan.
    bounds = (0.0, 0.0, 4.0, 3.0)
    world = BoxWorld([(1.94, 0.41, 3.5, 2.5)], bounds)
    fp = square(3.1, 0.84, 0.1)
    agent = Agent(world, 0.3, 0.71)
    res = navigate_to(agent, grid_of([(2.09, 0.59, 3.5, 2.5)], bounds), fp)
    assert "the same contact again" in res.reason and "which the map already holds" in res.reason
    assert sum("again; stopping" in e for e in res.events) == 1
    assert res.replans <= 6 and "gave up" not in res.reason
    # With every reachable goal refused, the reason says so: it never claims unknown space on a
    # map without any.
    assert "only unknown space" not in res.reason
    assert "ruled out as a goal" in res.reason
    assert res.reached == (dist(agent, fp) <= 1.0)


def _two_rooms(door_open: bool) -> OccupancyGrid:
    """A 6 x 3 m flat: rooms west and east of a wall at x = 3 m with a 0.9 m door, open or shut."""
    spec = GridSpec(0.0, 0.0, 0.05, 60, 120)
    cells = np.full((60, 120), FREE, np.uint8)
    cells[:2, :] = cells[-2:, :] = OCCUPIED
    cells[:, :2] = cells[:, -2:] = OCCUPIED
    cells[:, 59:61] = OCCUPIED  # the wall, x 2.95-3.05 m
    if door_open:
        cells[26:44, 59:61] = FREE  # the doorway, y 1.3-2.2 m
    return OccupancyGrid(spec, cells)


def test_a_goal_behind_a_closed_door_says_it_is_cut_off() -> None:
    fp = square(5.2, 1.0, 0.15)  # an object in the east room
    start = (1.0, 1.5)
    opened = select_goal(_two_rooms(True), fp, start)
    assert opened.reached_within_reach
    shut = select_goal(_two_rooms(False), fp, start)
    assert not shut.reached_within_reach
    assert "no reachable free cell within 1.00 m" in shut.reason
    assert "is not connected to where the robot stands on the map: a closed door" in shut.reason
    # an object whose every side is wall on the map (nothing free within reach) is not "cut off"
    boxed = _two_rooms(True)
    rr, cc = np.mgrid[0:60, 0:120]
    centres = boxed.spec.to_world(np.stack([rr.ravel(), cc.ravel()], axis=1)).reshape(60, 120, 2)
    inner = (np.abs(centres[..., 0] - 5.2) < 1.4) & (np.abs(centres[..., 1] - 1.0) < 1.4)
    boxed.cells[inner & ((np.abs(centres[..., 0] - 5.2) > 0.25) | (np.abs(centres[..., 1] - 1.0) > 0.25))] = OCCUPIED
    walled = select_goal(boxed, fp, start)
    assert not walled.reached_within_reach and "not connected" not in walled.reason
