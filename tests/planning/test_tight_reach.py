"""Right object, stopped too far: passages with just the robot's clearance, and contacts the map
already holds. The agent is the simulator's own (:class:`capnav.sim.agent.Agent`) in a world of
boxes; the planner sees a grid drawn from the same boxes, a few centimetres off, as a map is."""

from __future__ import annotations

from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np
from numpy.typing import NDArray

from capnav.core.footprint import footprint_distance
from capnav.core.grid import FREE, OCCUPIED, GridSpec, OccupancyGrid
from capnav.planning import navigate_to
from capnav.sim.agent import Agent
from capnav.sim.config import AgentConfig

Box = tuple[float, float, float, float]  # x0, y0, x1, y1


@dataclass
class BoxWorld:
    """Axis-aligned boxes the agent disk may not overlap, inside ``bounds``."""

    boxes: list[Box]
    bounds: Box
    config: SimpleNamespace = field(default_factory=lambda: SimpleNamespace(agent=AgentConfig()))

    @property
    def manifest(self) -> SimpleNamespace:
        return SimpleNamespace(bounds=self.bounds)

    def collides_many(self, xy: NDArray[np.floating]) -> NDArray[np.bool_]:
        p = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        r = self.config.agent.radius
        x0, y0, x1, y1 = self.bounds
        hit = (p[:, 0] < x0 + r) | (p[:, 0] > x1 - r) | (p[:, 1] < y0 + r) | (p[:, 1] > y1 - r)
        for bx0, by0, bx1, by1 in self.boxes:
            dx = np.maximum(np.maximum(bx0 - p[:, 0], 0.0), p[:, 0] - bx1)
            dy = np.maximum(np.maximum(by0 - p[:, 1], 0.0), p[:, 1] - by1)
            hit |= np.hypot(dx, dy) < r
        return hit

    def collides(self, x: float, y: float) -> bool:
        return bool(self.collides_many(np.array([[x, y]]))[0])

    def render(self, *args: object, **kwargs: object) -> None:  # pragma: no cover - never observed here
        raise NotImplementedError


def grid_of(boxes: list[Box], bounds: Box, res: float = 0.05) -> OccupancyGrid:
    """The map of the boxes: a cell is occupied when its centre lies in a box (or off ``bounds``)."""
    x0, y0, x1, y1 = bounds
    spec = GridSpec(x0 - 2 * res, y0 - 2 * res, res, round((y1 - y0) / res) + 4, round((x1 - x0) / res) + 4)
    rr, cc = np.mgrid[0:spec.rows, 0:spec.cols]
    c = spec.to_world(np.stack([rr.ravel(), cc.ravel()], axis=1))
    occ = (c[:, 0] < x0) | (c[:, 0] > x1) | (c[:, 1] < y0) | (c[:, 1] > y1)
    for bx0, by0, bx1, by1 in boxes:
        occ |= (c[:, 0] >= bx0) & (c[:, 0] <= bx1) & (c[:, 1] >= by0) & (c[:, 1] <= by1)
    return OccupancyGrid(spec, np.where(occ, OCCUPIED, FREE).astype(np.uint8).reshape(spec.rows, spec.cols))


def square(x: float, y: float, h: float) -> NDArray[np.float64]:
    return np.array([[x - h, y - h], [x + h, y - h], [x + h, y + h], [x - h, y + h]])


def dist(agent: Agent, fp: NDArray[np.float64]) -> float:
    return float(footprint_distance(np.asarray(agent.pose[:2]).reshape(1, 2), fp)[0])


def test_a_contact_the_map_already_holds_is_no_reason_to_replan_again() -> None:
    # The object stands deep in a block nobody can enter; the closest reachable cell is in front
    # of the block, but the world's block is 0.1 m thicker than the map's: the agent stops short of
    # that goal against an obstacle whose mark cannot cover the goal (the agent stands on it).
    bounds = (0.0, 0.0, 4.0, 3.0)
    mapped = [(2.6, 0.0, 4.0, 3.0)]
    world = BoxWorld([(2.5, 0.0, 4.0, 3.0)], bounds)
    fp = square(3.8, 1.5, 0.1)
    agent = Agent(world, 0.8, 1.5)
    res = navigate_to(agent, grid_of(mapped, bounds), fp)
    assert not res.reached
    assert res.replans <= 3, res.events  # it did not repeat a contact that taught it nothing
    assert not any(" 0 cells blocked; replanning" in e for e in res.events)
    assert "gave up" not in res.reason and res.reason.startswith("stopped 1.4")
    assert dist(agent, fp) < 1.45  # it stopped against the block (1.40 m is as close as the world allows)


def test_a_passage_with_just_the_robots_clearance_is_driven_through() -> None:
    # Two rooms joined by a corridor 0.42 m wide in the world (2 cm of slack for a 0.4 m robot),
    # drawn 0.40 m wide on the map: planning needs the relaxation under
    # the true radius and the agent must not seal the corridor by marking a graze.
    bounds = (0.0, 0.0, 6.0, 3.0)
    world_boxes = [(2.0, 0.0, 4.0, 1.29), (2.0, 1.71, 4.0, 3.0)]  # corridor y in [1.29, 1.71]
    map_boxes = [(2.0, 0.0, 4.0, 1.3), (2.0, 1.7, 4.0, 3.0)]
    fp = square(5.6, 2.6, 0.15)
    for start in [(0.6, 0.5), (0.6, 2.5), (1.0, 1.5)]:
        agent = Agent(BoxWorld(world_boxes, bounds), *start)
        res = navigate_to(agent, grid_of(map_boxes, bounds), fp)
        assert res.reached, (start, res.reason, res.events)
        assert dist(agent, fp) <= 1.0


def test_a_corner_grazed_on_the_way_into_a_tight_passage_is_slid_past() -> None:
    # A table whose mapped corner is 3 cm short of the world's: the path around it into the
    # corridor beside it grazes the corner. The agent slides off the graze instead of marking it.
    bounds = (0.0, 0.0, 4.0, 4.0)
    world_boxes = [(0.0, 1.5, 3.52, 2.5)]  # corridor between the table and the east wall: x in [3.52, 4.0]
    map_boxes = [(0.0, 1.5, 3.49, 2.5)]
    fp = square(3.0, 3.7, 0.2)
    agent = Agent(BoxWorld(world_boxes, bounds), 1.0, 0.5)
    res = navigate_to(agent, grid_of(map_boxes, bounds), fp)
    assert res.reached, (res.reason, res.events)
