"""Execution in the simulator: the agent reaches instances, logs its trajectory and recovers
from obstacles the map does not know about."""

from __future__ import annotations

import json

import numpy as np
import pytest

from capnav.core.errors import InputError
from capnav.core.footprint import footprint_distance
from capnav.core.grid import FREE, OccupancyGrid
from capnav.planning import PlannerConfig, build_costmap, navigate_to
from capnav.sim import Simulator

SEED = 1


@pytest.fixture(scope="module")
def sim():
    s = Simulator.from_seed(SEED)
    yield s
    s.close()


def dist_to(agent, fp) -> float:
    return float(footprint_distance(np.asarray(agent.pose[:2]).reshape(1, 2), fp)[0])


def test_reaches_instances_on_the_true_map(sim) -> None:
    occ = sim.obstacles()
    cfg = PlannerConfig()
    cm = build_costmap(occ, cfg)
    rng = np.random.default_rng(0)
    for inst in sim.manifest.objects[::4]:
        fp = np.asarray(inst.footprint)
        x, y = sim.random_navigable_point(rng)
        agent = sim.spawn_agent(x, y, 0.0)
        res = navigate_to(agent, occ, fp, cfg, cm)
        assert res.reached, (inst.id, res.reason)
        assert dist_to(agent, fp) <= 1.0
        assert res.final_pose == pytest.approx(agent.pose)
        # The log is the agent's own motion: same start, same end, same length.
        assert np.allclose(res.trajectory[0], (x, y)) and np.allclose(res.trajectory[-1], agent.pose[:2])
        assert res.path_length == pytest.approx(agent.path_length, abs=1e-6)
        assert res.path_length >= np.linalg.norm(np.diff(res.waypoints, axis=0), axis=1).sum() - 1e-6
        assert agent.collisions == 0
        # Facing the object at the end (within half a turn step).
        centre = fp.mean(axis=0)
        want = np.arctan2(centre[1] - agent.pose[1], centre[0] - agent.pose[0])
        assert abs((agent.pose[2] - want + np.pi) % (2 * np.pi) - np.pi) <= np.radians(15) + 0.05
        json.dumps(res.to_dict())


def furniture_free(sim, every: int = 3) -> OccupancyGrid:
    """The true map with every ``every``-th piece of furniture erased: obstacles the map missed."""
    occ = sim.obstacles()
    rr, cc = np.mgrid[0:occ.spec.rows, 0:occ.spec.cols]
    centres = occ.spec.to_world(np.stack([rr.ravel(), cc.ravel()], axis=1))
    cells = occ.cells.copy().ravel()
    for inst in sim.manifest.objects[::every]:
        inside = footprint_distance(centres, np.asarray(inst.footprint)) <= occ.spec.resolution
        cells[inside] = FREE
    return OccupancyGrid(occ.spec, cells.reshape(occ.cells.shape))


def test_collisions_mark_the_map_and_replan(sim) -> None:
    occ = furniture_free(sim)
    cfg = PlannerConfig()
    rng = np.random.default_rng(1)
    total_replans, reached = 0, 0
    targets = [o for i, o in enumerate(sim.manifest.objects) if i % 3 != 0]
    for inst in targets:
        fp = np.asarray(inst.footprint)
        x, y = sim.random_navigable_point(rng)
        agent = sim.spawn_agent(x, y, 0.0)
        res = navigate_to(agent, occ, fp, cfg)
        total_replans += res.replans
        # Every contact led to one replan (the bumper probes add contacts of their own).
        assert sum(e.endswith("replanning") for e in res.events) == res.replans <= agent.collisions
        reached += dist_to(agent, fp) <= 1.0
    assert total_replans > 0  # the furniture really was in the way
    assert reached == len(targets)
    # The caller's map is untouched by the contact marks.
    assert (occ.cells == furniture_free(sim).cells).all()


class StepOnly:
    """The simulator agent seen through discrete actions only (a robot without a waypoint follower)."""

    def __init__(self, agent) -> None:
        self._agent = agent
        self.cfg = agent.cfg

    @property
    def pose(self):
        return self._agent.pose

    def step(self, action: str) -> bool:
        return self._agent.step(action)


def test_discrete_actions_reach_the_goal(sim) -> None:
    occ = sim.obstacles()
    rng = np.random.default_rng(2)
    inst = sim.manifest.objects[3]
    x, y = sim.random_navigable_point(rng)
    agent = sim.spawn_agent(x, y, 0.0)
    res = navigate_to(StepOnly(agent), occ, np.asarray(inst.footprint), PlannerConfig())
    assert res.reached and dist_to(agent, np.asarray(inst.footprint)) <= 1.0
    assert agent.steps > 3 and res.path_length == pytest.approx(agent.path_length, abs=1e-6)


def test_start_inside_an_obstacle_is_an_input_error(sim) -> None:
    occ = sim.obstacles()
    inst = sim.manifest.objects[0]

    class Stuck:
        pose = (float(inst.center[0]), float(inst.center[1]), 0.0)

        def step(self, action: str) -> bool:
            raise AssertionError("must not move")

    with pytest.raises(InputError, match="inside an obstacle"):
        navigate_to(Stuck(), occ, np.asarray(sim.manifest.objects[1].footprint))


def test_unreachable_object_stops_at_the_closest_cell_with_the_reason(sim) -> None:
    occ = sim.obstacles()
    inst = max(sim.manifest.objects, key=lambda o: o.size[0] * o.size[1])
    fp = np.asarray(inst.footprint)
    # The map claims a wall ring 1.2-1.4 m around the object: nothing within reach is reachable.
    rr, cc = np.mgrid[0:occ.spec.rows, 0:occ.spec.cols]
    d = footprint_distance(occ.spec.to_world(np.stack([rr.ravel(), cc.ravel()], axis=1)), fp).reshape(rr.shape)
    cells = occ.cells.copy()
    cells[(d > 1.2) & (d < 1.4)] = 1
    walled = OccupancyGrid(occ.spec, cells)
    free = sim.navigable().spec.to_world(np.argwhere((sim.navigable().cells == FREE) & (d > 2.0)))
    x, y = free[len(free) // 2]
    agent = sim.spawn_agent(float(x), float(y), 0.0)
    res = navigate_to(agent, walled, fp)
    assert not res.reached and res.goal is not None and not res.goal.reached_within_reach
    assert "no reachable free cell within 1.00 m" in res.reason
    assert 1.0 < res.distance_to_object < 2.0  # it went as close as the map allows


class Retracer:
    """A thin agent that drives anywhere (the map's walls are thicker than the world's) and keeps its trajectory."""

    def __init__(self, path: list[tuple[float, float]]) -> None:
        self.trajectory = list(path)

    @property
    def pose(self) -> tuple[float, float, float]:
        return (*self.trajectory[-1], 0.0)

    def move_to(self, x: float, y: float) -> bool:
        self.trajectory.append((x, y))
        return True


def test_boxed_in_it_backs_out_the_way_it_came_and_says_so() -> None:
    from capnav.core.grid import OCCUPIED, GridSpec

    # A room east of x = 1.6 m and a dead-end corridor 0.3 m wide west of it, narrower on the map
    # than any relaxation lets the 0.2 m robot plan in: from its end there is no plan at all.
    spec = GridSpec(0.0, 0.0, 0.05, 60, 120)
    cells = np.full((60, 120), OCCUPIED, np.uint8)
    cells[3:57, 32:117] = FREE  # the room, x 1.6-5.85 m
    cells[27:33, 18:32] = FREE  # the corridor, x 0.9-1.6 m, y 1.35-1.65 m
    occ = OccupancyGrid(spec, cells)
    fp = np.array([[4.4, 1.4], [4.6, 1.4], [4.6, 1.6], [4.4, 1.6]])
    agent = Retracer([(3.0, 1.5), (2.0, 1.5), (1.0, 1.5)])
    res = navigate_to(agent, occ, fp)
    assert res.reached and res.recovery and res.recovery[0].startswith("backed out 0.50 m along the way it came")
    assert "recovery" in res.to_dict() and any("backed out" in e for e in res.events)
    # without a way it came, the same spot is the user's error with its reason
    with pytest.raises(InputError, match="no free cell within"):
        navigate_to(Retracer([(1.0, 1.5)]), occ, fp)
