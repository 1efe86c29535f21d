"""The explorer's drive past convex corners and through gaps a few centimetres wider than the robot.

A search plans at a relaxed inflation (the bare radius less half a cell, ``explore/levels.py``) so
that a door the 0.2 m robot fits through stays open; its path then passes corners closer than the
robot, and the robot follows it at the nearest 30-degree heading in 0.25 m steps. On seed 100
(s100001, s100002) every first step of every replan touched the same corner ("could not get to ...
giving it up" 3-5 times without moving: wedged between an ottoman and an armchair, at an armchair's
corner by a door), and the contact mark stamped straight ahead sat in the gap the robot was passing.

Here a disc robot that stops at the contact, as the simulator's agent does (``sim/agent.py``),
drives on a saved map of box furniture (its cells those the boxes overlap, as depth marks them).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "mapping"))
from _synth_scene import ROOM, Box, render

from capnav.core.frame import Frame
from capnav.core.geometry import Intrinsics, look_at_pose
from capnav.core.grid import FREE, OCCUPIED, GridSpec, OccupancyGrid
from capnav.explore.explorer import ExplorerConfig, FrontierExplorer, Status
from capnav.explore.levels import search_levels
from capnav.explore.online_map import OnlineMap, OnlineMapConfig
from capnav.planning import PlannerConfig

K = Intrinsics.from_fov(160, 120, 70.0)
WALL = (225, 225, 215)


class DiscAgent:
    """A 0.2 m disc in the box world: 30-degree turns, 0.25 m steps that stop at the first contact
    (to the millimetre), a camera at 1.2 m."""

    class cfg:
        turn_deg = 30.0
        forward_step = 0.25

    def __init__(self, boxes: list[Box], x: float, y: float, yaw: float = 0.0, radius: float = 0.2) -> None:
        self.boxes, self.x, self.y, self.yaw, self.r = boxes, x, y, yaw, radius
        self.path_length = 0.0
        self.frames = 0
        self.contacts = 0
        assert self._free(x, y)

    @property
    def pose(self) -> tuple[float, float, float]:
        return self.x, self.y, self.yaw

    def clearance(self) -> float:
        return min(math.hypot(max(b.lo[0] - self.x, 0.0, self.x - b.hi[0]),
                              max(b.lo[1] - self.y, 0.0, self.y - b.hi[1])) for b in self.boxes)

    def _free(self, x: float, y: float) -> bool:
        r = self.r
        if not (ROOM[0][0] + r <= x <= ROOM[1][0] - r and ROOM[0][1] + r <= y <= ROOM[1][1] - r):
            return False
        return all(max(b.lo[0] - x, 0.0, x - b.hi[0]) ** 2 + max(b.lo[1] - y, 0.0, y - b.hi[1]) ** 2 >= r * r
                   for b in self.boxes)

    def step(self, action: str) -> bool:
        if action in ("turn_left", "turn_right"):
            self.yaw += math.radians(30.0 if action == "turn_left" else -30.0)
            return True
        gx, gy = self.x + 0.25 * math.cos(self.yaw), self.y + 0.25 * math.sin(self.yaw)
        lo, hi, ok = 0.0, 1.0, True
        for t in np.linspace(0.02, 1.0, 13):
            if not self._free(self.x + t * (gx - self.x), self.y + t * (gy - self.y)):
                hi, ok = float(t), False
                break
            lo = float(t)
        while not ok and hi - lo > 0.004:
            m = 0.5 * (lo + hi)
            if self._free(self.x + m * (gx - self.x), self.y + m * (gy - self.y)):
                lo = m
            else:
                hi = m
        self.contacts += not ok
        nx, ny = self.x + lo * (gx - self.x), self.y + lo * (gy - self.y)
        self.path_length += math.dist((nx, ny), (self.x, self.y))
        self.x, self.y = nx, ny
        return ok

    def observe(self) -> Frame:
        self.frames += 1
        return render(self.boxes, look_at_pose(np.array([self.x, self.y, 1.2]), self.yaw, math.radians(20)), K,
                      index=self.frames)


def _saved_map(boxes: list[Box], res: float = 0.05) -> OccupancyGrid:
    """The room's occupancy as a map holds it: every cell a box overlaps is occupied."""
    n = round((ROOM[1][0] - ROOM[0][0]) / res)
    spec = GridSpec(ROOM[0][0], ROOM[0][1], res, n, n)
    cells = np.full((n, n), FREE, np.uint8)
    for b in boxes:
        c0, c1 = math.floor((b.lo[0] - spec.x0) / res), math.ceil((b.hi[0] - spec.x0) / res)
        r0, r1 = math.floor((b.lo[1] - spec.y0) / res), math.ceil((b.hi[1] - spec.y0) / res)
        cells[max(r0, 0):r1, max(c0, 0):c1] = OCCUPIED
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = OCCUPIED
    return OccupancyGrid(spec, cells)


def _explorer(boxes: list[Box], start: tuple[float, float], yaw: float = 0.0) -> tuple[DiscAgent, FrontierExplorer]:
    agent = DiscAgent(boxes, *start, yaw)
    online = OnlineMap((0.0, 0.0), OnlineMapConfig(resolution=0.05, half_extent=6.0), _saved_map(boxes))
    ex = FrontierExplorer(agent, None, ExplorerConfig(keyframe_turn_deg=30.0), online)
    ex.begin(400)
    return agent, ex


def _relaxed() -> PlannerConfig:
    """The loosest inflation a search plans with (0.175 m): where these drives are planned."""
    planner = search_levels(PlannerConfig(), 0.05)[-1].planner
    assert abs(planner.inflation - 0.175) < 1e-9
    return planner


def _gap(x0: float = 0.32, width: float = 0.46) -> list[Box]:
    """An ottoman and an armchair side by side across the room, a gap of ``width`` between them."""
    return [Box((-3.0, 0.0, 0.0), (x0, 0.4, 0.45), 1, 3, (200, 30, 30)),
            Box((x0 + width, 0.0, 0.0), (3.0, 0.4, 0.8), 2, 1, (30, 30, 200))]


def test_a_gap_a_few_centimetres_wider_than_the_robot_is_driven_through() -> None:
    """A 0.46 m gap (the robot is 0.40 m wide) met at an angle: the step into it touches a side,
    and every replan from the contact headed into the same side (blocked after 1-4 contacts,
    0.5 m short of the gap). A blocked step is slid off (a heading that leaves the contact), and
    the partial step of a contact sets the robot where the gap takes it."""
    boxes = _gap()
    for start in ((-1.5, -2.0), (-1.5, -1.0)):
        agent, ex = _explorer(boxes, start)
        st = ex.drive_to((1.8, 1.8), planner=_relaxed())
        assert st is Status.ARRIVED, (start, st, agent.pose)
        assert agent.y > 1.0 and agent.contacts <= 4


def test_an_armchairs_corner_by_a_door_is_driven_past() -> None:
    """A door 0.9 m wide and, beyond it, an armchair whose corner stands 0.45 m from the door's
    post: the way through bends round both corners; at 0.175 m the plan cuts them."""
    walls = [Box((0.6, -3.0, 0.0), (0.75, -0.45, 2.5), 0, 0, WALL), Box((0.6, 0.45, 0.0), (0.75, 3.0, 2.5), 0, 0, WALL)]
    chair = Box((1.2, -0.35, 0.0), (2.0, 0.55, 0.8), 3, 3, (200, 30, 30))
    for start, goal in (((-1.5, -2.0), (2.3, 2.0)), ((-2.0, 0.3), (2.3, 2.0)), ((-1.0, 1.5), (2.2, -1.8))):
        agent, ex = _explorer([*walls, chair], start)
        st = ex.drive_to(goal, planner=_relaxed())
        assert st is Status.ARRIVED, (start, goal, st, agent.pose)
        assert agent.x > 0.75


def test_a_contact_at_the_robots_side_is_marked_there_not_in_the_gap_ahead() -> None:
    """The robot in the gap's mouth, its left side touching the ottoman's corner, steps straight
    on: the step is blocked. The mark goes on the line to the known corner it touched; stamped
    straight ahead (0.26 m) it closed the gap the robot was passing through."""
    boxes = _gap()
    agent, ex = _explorer(boxes, (0.516, -0.06), math.radians(90))
    ex.observe()
    assert not ex.act("move_forward") and agent.contacts == 1
    cells = ex.map.cells()
    spec = ex.map.spec
    mid = spec.to_cell(np.array([[0.55, y] for y in np.arange(0.0, 0.45, 0.05)]))
    assert (cells[mid[:, 0], mid[:, 1]] == FREE).all()  # the gap's middle stays open
    near = spec.to_cell(np.array([[0.30, 0.0]]))[0]
    assert cells[near[0], near[1]] == OCCUPIED
