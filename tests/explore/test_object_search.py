"""The search of ``navigate --search`` in two box rooms joined by a door: the first map saw only
room A. An object in room B (a room the map never saw) is searched for and reached; a chair the
map has in room A but that was carried into room B is not at its place, so the robot searches and
finds it there (not the red chair that stayed); an object that is nowhere ends the search with
"not found within budget". The request is answered by the retriever of ``capnav query`` on the map
plus what the robot has seen: the first plant seen is not "the plant next to the lamp" before a
lamp is seen, nor "the biggest plant" when a bigger one is in view."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "mapping"))
from _synth_scene import ROOM, Box, HashEmbedder, render

from capnav.core.frame import Frame
from capnav.core.geometry import Intrinsics, look_at_pose
from capnav.explore.search import ObjectSearch, SearchConfig
from capnav.language import create_captioner, create_embedder, describe_map
from capnav.mapping import CapNavMap, build_map
from capnav.perception import create_detector, create_encoder
from capnav.retrieval.retriever import Retriever

SOFA, CHAIR, TABLE, LAMP, PLANT = 1, 3, 5, 15, 16
BLUE, RED = (30, 40, 200), (200, 30, 30)
WALLS = [Box((0.6, -3.0, 0.0), (0.75, -0.5, 2.5), 0, 0, (225, 225, 215)),
         Box((0.6, 0.5, 0.0), (0.75, 3.0, 2.5), 0, 0, (225, 225, 215))]
K = Intrinsics.from_fov(160, 120, 70.0)


def _room_a(blue_chair_xy: tuple[float, float]) -> list[Box]:
    x, y = blue_chair_xy
    return [*WALLS,
            Box((-2.5, -2.5, 0.0), (-0.8, -1.7, 0.8), 1, SOFA, (200, 200, 210)),
            Box((-2.4, 1.2, 0.0), (-1.4, 2.2, 0.75), 2, TABLE, (120, 80, 40)),
            Box((x - 0.25, y - 0.25, 0.0), (x + 0.25, y + 0.25, 0.9), 3, CHAIR, BLUE),
            Box((-2.5, -0.3, 0.0), (-2.0, 0.2, 0.9), 6, CHAIR, RED),
            Box((2.2, -2.5, 0.0), (2.5, -2.2, 1.6), 5, LAMP, (240, 220, 90))]


class BoxAgent:
    """A disc robot in the box world: turns of 30 degrees, steps of 0.25 m, a camera at 1.2 m."""

    class cfg:
        turn_deg = 30.0
        forward_step = 0.25

    def __init__(self, boxes: list[Box], x: float, y: float, yaw: float = 0.0) -> None:
        self.boxes, self.x, self.y, self.yaw = boxes, x, y, yaw
        self.path_length = 0.0
        self.frames = 0

    @property
    def pose(self) -> tuple[float, float, float]:
        return self.x, self.y, self.yaw

    def _free(self, x: float, y: float, r: float = 0.2) -> bool:
        if not (ROOM[0][0] + r <= x <= ROOM[1][0] - r and ROOM[0][1] + r <= y <= ROOM[1][1] - r):
            return False
        return not any(b.lo[0] - r <= x <= b.hi[0] + r and b.lo[1] - r <= y <= b.hi[1] + r for b in self.boxes)

    def step(self, action: str) -> bool:
        if action == "turn_left":
            self.yaw += math.radians(30)
            return True
        if action == "turn_right":
            self.yaw -= math.radians(30)
            return True
        nx, ny = self.x + 0.25 * math.cos(self.yaw), self.y + 0.25 * math.sin(self.yaw)
        if not self._free(nx, ny):
            return False
        self.x, self.y = nx, ny
        self.path_length += 0.25
        return True

    def observe(self) -> Frame:
        self.frames += 1
        return render(self.boxes, look_at_pose(np.array([self.x, self.y, 1.2]), self.yaw, math.radians(20)), K,
                      index=self.frames)


@pytest.fixture(scope="module")
def first_map() -> CapNavMap:
    """Room A recorded from its middle, never looking through the door: room B is unseen."""
    boxes = _room_a((-0.3, 2.0))
    frames = []
    for i, yaw in enumerate(np.radians(np.linspace(55, 305, 24))):
        for j, eye in enumerate(((-1.2, 0.0), (-1.8, 0.4))):
            T = look_at_pose(np.array([*eye, 1.2]), float(yaw), math.radians(25))
            frames.append(render(boxes, T, K, index=2 * i + j))
    cmap = _captioned(build_map(frames, detector=create_detector("sim", noise="oracle", seed=0),
                                encoder=create_encoder("label-embedding", embedder=HashEmbedder()), progress=False))
    labels = sorted(o.label for o in cmap.objects)
    assert "lamp" not in labels and labels.count("chair") == 2, labels
    return cmap


_EMB: list[object] = []


def _captioned(cmap: CapNavMap) -> CapNavMap:
    if not _EMB:
        _EMB.append(create_embedder("minilm"))
    describe_map(cmap, None, create_captioner("offline"), _EMB[0], progress=False)  # type: ignore[arg-type]
    return cmap


def _search(cmap: CapNavMap, world: list[Box], instruction: str, budget: float = 40.0):  # type: ignore[no-untyped-def]
    agent = BoxAgent(world, -1.2, -0.8, 0.0)
    retriever = Retriever(cmap, _EMB[0])  # type: ignore[arg-type]
    s = ObjectSearch(cmap, agent, create_detector("sim", noise="oracle", seed=0), retriever,
                     SearchConfig(budget_m=budget))
    return agent, s.run(instruction)


def _gap(agent: BoxAgent, box: Box) -> float:
    """Distance from the robot to a box's footprint."""
    gap = np.maximum(0.0, np.maximum(np.array(box.lo[:2]) - agent.pose[:2], np.array(agent.pose[:2]) - box.hi[:2]))
    return float(np.hypot(*gap))


def test_object_in_a_room_the_map_never_saw_is_found(first_map: CapNavMap) -> None:
    world = _room_a((-0.3, 2.0))
    agent, res = _search(first_map, world, "the lamp")
    assert res.found, res.reason
    lamp = next(b for b in world if b.category == LAMP)
    assert _gap(agent, lamp) <= 1.0
    assert res.steps[0].action == "map" and "not in the map" in res.steps[0].reason
    assert res.steps[1].action == "look"
    assert any("frontier" in s.reason for s in res.steps if s.action == "search")
    assert res.steps[-1].action == "found" and res.driven_m > 0


def test_object_not_where_the_map_says_is_searched_and_found(first_map: CapNavMap) -> None:
    world = _room_a((1.9, 1.9))  # the blue chair was carried into room B
    agent, res = _search(first_map, world, "the blue chair")
    assert res.found and not res.from_map, res.reason
    assert math.dist(agent.pose[:2], (1.9, 1.9)) <= 1.3
    text = " | ".join(s.reason for s in res.steps)
    assert "the map has it" in text and "asked again" in text


def test_a_new_colour_where_a_known_object_stood_is_not_that_object(first_map: CapNavMap) -> None:
    """The red chair was thrown out and the blue one set down exactly there: a blue chair seen on
    the map's red chair is the blue one, not the red one the map holds."""
    world = [b for b in _room_a((-2.25, -0.05)) if b.color != RED]
    agent, res = _search(first_map, world, "the blue chair")
    assert res.found and not res.from_map, res.reason
    assert math.dist(agent.pose[:2], (-2.25, -0.05)) <= 1.3


def test_the_goal_beside_the_robot_is_seen_before_it_leaves(first_map: CapNavMap) -> None:
    """The blue chair now stands beside the start, the map has it across the room: the robot looks
    around first and goes to the one it sees, not to the map's place."""
    world = _room_a((-0.2, -1.4))
    _, res = _search(first_map, world, "the blue chair")
    assert res.found and res.driven_m <= 1.5, res.reason
    assert [s.action for s in res.steps][:2] == ["map", "look"] and "found" in [s.action for s in res.steps[:4]]


def test_a_colour_of_a_part_is_searched_for(first_map: CapNavMap) -> None:
    """"The plant in the blue pot": a plant whose leaves are most of its mask and whose pot is a
    quarter to a third of it is the goal; a colour need not be the object's largest."""
    plant = [Box((1.75, 1.55, 0.0), (2.25, 2.05, 0.4), 9, PLANT, BLUE),  # the pot
             Box((1.75, 1.55, 0.4), (2.25, 2.05, 1.0), 9, PLANT, (40, 140, 50))]  # the leaves
    agent, res = _search(first_map, [*_room_a((-0.3, 2.0)), *plant], "the plant in the blue pot")
    assert res.found, res.reason
    assert math.dist(agent.pose[:2], (2.0, 1.8)) <= 1.3


def test_a_newcomer_in_the_colour_of_a_part_of_the_old_one_is_new(first_map: CapNavMap) -> None:
    """The map's red chair had dark legs; a black chair set down at its place is new, not it: the
    known object is compared by its main colour, not by any of its parts."""
    legs = Box((-2.5, -0.3, 0.0), (-2.0, 0.2, 0.55), 6, CHAIR, (25, 25, 28))
    seat = Box((-2.5, -0.3, 0.55), (-2.0, 0.2, 0.9), 6, CHAIR, RED)
    mapped = [b for b in _room_a((-0.3, 2.0)) if b.color != RED] + [legs, seat]
    frames = [render(mapped, look_at_pose(np.array([*eye, 1.2]), float(yaw), math.radians(25)), K, index=2 * i + j)
              for i, yaw in enumerate(np.radians(np.linspace(55, 305, 24)))
              for j, eye in enumerate(((-1.2, 0.0), (-1.8, 0.4)))]
    cmap = _captioned(build_map(frames, detector=create_detector("sim", noise="oracle", seed=0),
                                encoder=create_encoder("label-embedding", embedder=HashEmbedder()), progress=False))
    black = Box((-2.5, -0.3, 0.0), (-2.0, 0.2, 0.9), 7, CHAIR, (25, 25, 28))
    world = [b for b in _room_a((-0.3, 2.0)) if b.color != RED] + [black]
    agent, res = _search(cmap, world, "the black chair")
    assert res.found, res.reason
    assert math.dist(agent.pose[:2], (-2.25, -0.05)) <= 1.3


def test_the_first_plant_seen_is_not_the_one_next_to_the_lamp(first_map: CapNavMap) -> None:
    """Two plants the map never saw: one in view through the door from the start, one beside the
    lamp in the corner of room B that no first view shows. The first is not the answer before a
    lamp has been seen; the search goes on until it sees the lamp and the plant beside it."""
    near_door = Box((2.2, 0.2, 0.0), (2.6, 0.6, 0.8), 20, PLANT, (40, 140, 50))
    by_lamp = Box((1.7, -2.6, 0.0), (2.1, -2.2, 0.8), 21, PLANT, (40, 140, 50))
    world = [*_room_a((-0.3, 2.0)), near_door, by_lamp]
    agent, res = _search(first_map, world, "the plant next to the lamp")
    assert res.found, res.reason
    assert _gap(agent, by_lamp) <= 1.0 and _gap(agent, by_lamp) < _gap(agent, near_door), (agent.pose, res.reason)
    text = " | ".join(s.reason for s in res.steps)
    assert "no lamp seen yet" in text, text


def test_the_biggest_plant_is_compared_with_the_others_seen(first_map: CapNavMap) -> None:
    """Two new plants in view from the start, a small one close by and a big one across the room:
    "the biggest plant" is the big one, not the nearer first sighting of a plant."""
    small = Box((0.0, -2.3, 0.0), (0.3, -2.0, 0.45), 20, PLANT, (40, 140, 50))
    big = Box((-1.9, 0.3, 0.0), (-1.3, 0.9, 1.4), 21, PLANT, (40, 140, 50))
    world = [*_room_a((-0.3, 2.0)), small, big]
    agent, res = _search(first_map, world, "the biggest plant")
    assert res.found, res.reason
    assert _gap(agent, big) <= 1.0 and _gap(agent, big) < _gap(agent, small), (agent.pose, res.reason)


def test_budget_running_out_says_so(first_map: CapNavMap) -> None:
    world = _room_a((-0.3, 2.0))
    _, res = _search(first_map, world, "the bookshelf", budget=3.0)
    assert not res.found
    assert res.reason.startswith("not found within budget: drove"), res.reason
    assert res.driven_m <= 3.0 + 0.25


def test_search_refuses_a_map_of_a_recording(first_map: CapNavMap, tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from capnav.cli import app
    from capnav.core.errors import InputError
    from capnav.io.mapfile import save_map

    assert "scene_seed" not in first_map.meta  # made from frames, not from capnav sim
    path = tmp_path / "recorded.capnav"
    save_map(first_map, path)
    res = CliRunner().invoke(app, ["navigate", str(path), "the lamp", "--search", "--out", str(tmp_path / "o")])
    assert isinstance(res.exception, InputError), res.output
    msg = str(res.exception)
    assert "--search drives the simulated robot" in msg and "no simulator scene (no scene seed)" in msg
    assert "drop --search" in msg


def _search_with(cmap: CapNavMap, world: list[Box], instruction: str, marks: list[tuple[float, float]]
                 ):  # type: ignore[no-untyped-def]
    """``_search`` with contact marks already on the robot's online map (grazes of earlier drives)."""
    agent = BoxAgent(world, -1.2, -0.8, 0.0)
    s = ObjectSearch(cmap, agent, create_detector("sim", noise="oracle", seed=0), Retriever(cmap, _EMB[0]),
                     SearchConfig(budget_m=40.0))  # type: ignore[arg-type]
    for xy in marks:
        s.explorer.map.mark_obstacle(xy)
    return agent, s.run(instruction)


def test_a_door_closed_by_the_robots_own_contact_marks_is_tried_again(first_map: CapNavMap) -> None:
    """Two grazes of the door posts left contact marks in the doorway, where the depth sees bare
    floor: every place in room B looked unreachable and the search ended in room A ("no place left
    to look from can be reached"). The search plans without those marks once nothing else is
    reachable, and finds the lamp."""
    world = _room_a((-0.3, 2.0))
    agent, res = _search_with(first_map, world, "the lamp", [(0.68, -0.12), (0.68, 0.12)])
    assert res.found, res.reason
    assert _gap(agent, next(b for b in world if b.category == LAMP)) <= 1.0
    assert any("contact marks on floor seen free forgiven" in s.reason for s in res.steps), res.steps


def test_a_door_narrower_than_the_robot_and_its_margin_is_planned_through(first_map: CapNavMap) -> None:
    """A 0.52 m door: the 0.2 m robot fits, its 0.25 m inflation (radius and margin) does not. The
    search relaxes the inflation as CapNav's own execution does, instead of ending in room A."""
    walls = [Box((0.6, -3.0, 0.0), (0.75, -0.26, 2.5), 0, 0, (225, 225, 215)),
             Box((0.6, 0.26, 0.0), (0.75, 3.0, 2.5), 0, 0, (225, 225, 215))]
    world = walls + _room_a((-0.3, 2.0))[len(WALLS):]
    agent, res = _search_with(first_map, world, "the lamp", [])
    assert res.found, res.reason
    assert _gap(agent, next(b for b in world if b.category == LAMP)) <= 1.0
    assert any("planning with inflation 0.200 m" in s.reason for s in res.steps), res.steps


def test_path_lengths_agree_with_the_drive_planner() -> None:
    """Every place the search's path lengths call reachable is one the drive plans to (the start
    snapped as the planner snaps it, a blocked target looked at from a passable cell within reach),
    and no other: a start boxed in between a cabinet and a wall is not snapped behind the wall."""
    from capnav.core.errors import CapNavError
    from capnav.core.grid import FREE, OCCUPIED, GridSpec, OccupancyGrid
    from capnav.explore.search import path_lengths
    from capnav.planning import PlannerConfig, build_costmap, plan_path

    spec = GridSpec(0.0, 0.0, 0.05, 60, 80)  # 4 x 3 m
    cells = np.full((60, 80), FREE, np.uint8)
    cells[:, 40:43] = OCCUPIED  # a wall at x 2.00-2.15 ...
    cells[22:38, 40:43] = FREE  # ... with a 0.8 m door at y 1.1-1.9
    cells[:20, 29:31] = OCCUPIED  # a cabinet's side at x 1.45-1.55, y 0-1: a 0.45 m gap beside the wall
    cells[52:, 60:] = OCCUPIED  # a block in room B's corner (x 3-4, y 2.6-3)
    grid = OccupancyGrid(spec, cells)
    cfg = PlannerConfig()
    cm = build_costmap(grid, cfg)
    targets = [(3.5, 0.5), (3.5, 2.2), (0.5, 0.5), (1.78, 2.8), (3.5, 2.95), (1.78, 0.4)]
    reach = 1.0

    def drivable(start: tuple[float, float], t: tuple[float, float]) -> bool:
        rc = spec.to_cell(np.asarray(t))
        k = int(np.ceil(reach / spec.resolution))
        goals = [t] if np.isfinite(cm.weights[rc[0], rc[1]]) else [
            (float(x), float(y)) for x, y in spec.to_world(np.argwhere(np.isfinite(cm.weights)))
            if math.dist((x, y), t) <= reach and abs(x - t[0]) <= k * spec.resolution]
        for g in goals:
            try:
                plan_path(grid, start, g, cfg, cm)
                return True
            except CapNavError:
                continue
        return False

    for start in ((0.5, 2.0), (1.78, 0.5)):  # in room A; boxed in the gap (no passable cell within 0.5 m)
        got = path_lengths(grid, cm, start, targets, cfg, reach)
        for t, d in zip(targets, got, strict=True):
            assert drivable(start, t) == bool(np.isfinite(d)), (start, t, d)
    assert np.isfinite(path_lengths(grid, cm, (0.5, 2.0), targets, cfg, reach)).sum() >= 5
    assert not np.isfinite(path_lengths(grid, cm, (1.78, 0.5), targets, cfg, reach)).any()


def test_a_look_from_behind_a_wall_does_not_spend_a_place(first_map: CapNavMap) -> None:
    """A place to look from in room A 1.2 m from where the robot looked around in room B, the wall
    between them: that look saw nothing of the place. Nor does aiming at a place nearby that could
    not be stood on and was looked from elsewhere (s100001: a room's standing point 1.4 m from one
    the robot aimed at and looked from a metre off, spent unseen, its new plant never seen). A look
    from as near on the place's own side of the wall does spend it."""
    from capnav.explore.places import Place, room_places

    agent = BoxAgent(_room_a((-0.3, 2.0)), -1.2, -0.8, 0.0)
    s = ObjectSearch(first_map, agent, create_detector("sim", noise="oracle", seed=0), Retriever(first_map, _EMB[0]),
                     SearchConfig())  # type: ignore[arg-type]
    _, regions = room_places(first_map, "plant", _EMB[0])  # type: ignore[arg-type]
    s._looked_in = set()
    here = (0.1, -1.5)
    rc = first_map.occupancy.spec.to_cell(np.asarray(here))
    place = Place(here, int(regions[rc[0], rc[1]]), 0.5, "room A by the wall")
    s._spots = [(1.3, -1.5)]  # looked around in room B, 1.2 m away, behind the wall
    assert not s._spent(place, [], regions)
    # Aimed at a place in room A 1.1 m away that could not be stood on, looked from room B.
    assert not s._spent(place, [(-1.0, -1.5)], regions)
    s._spots.append((-1.0, -1.4))  # looked around in room A, 1.1 m away, in the open
    assert s._spent(place, [], regions)


def test_the_biggest_plant_carried_off_is_looked_for_before_a_smaller_one_is_taken() -> None:
    """The first map holds a big plant and a small one in room A; the big one was carried into room
    B. From the start the robot sees the big one's place empty and the small one at its place:
    "the biggest plant" is not the small one (confirmed at its place, and it was the answer with
    the search of 5a9081c) while the bigger one the map saw gone may stand elsewhere; the search
    looks on, finds it in room B and goes there."""
    small = Box((0.0, -2.3, 0.0), (0.3, -2.0, 0.45), 20, PLANT, (40, 140, 50))
    big_at = ((-1.9, 0.3), (-1.3, 0.9))
    big = Box((*big_at[0], 0.0), (*big_at[1], 1.4), 21, PLANT, (40, 140, 50))
    mapped = [*_room_a((-0.3, 2.0)), small, big]
    frames = [render(mapped, look_at_pose(np.array([*eye, 1.2]), float(yaw), math.radians(25)), K, index=2 * i + j)
              for i, yaw in enumerate(np.radians(np.linspace(55, 305, 24)))
              for j, eye in enumerate(((-1.2, 0.0), (-1.8, 0.4)))]
    cmap = _captioned(build_map(frames, detector=create_detector("sim", noise="oracle", seed=0),
                                encoder=create_encoder("label-embedding", embedder=HashEmbedder()), progress=False))
    assert sorted(o.label for o in cmap.objects).count("plant") == 2
    moved = Box((1.7, 1.5, 0.0), (2.3, 2.1, 1.4), 21, PLANT, (40, 140, 50))
    world = [*_room_a((-0.3, 2.0)), small, moved]
    agent, res = _search(cmap, world, "the biggest plant")
    assert res.found, res.reason
    assert _gap(agent, moved) <= 1.0 and _gap(agent, small) > 1.0, (agent.pose, res.reason)
    assert any("held back" in s.reason for s in res.steps), [s.reason for s in res.steps]


def test_a_place_beyond_a_narrow_door_is_weighed_with_the_rest(first_map: CapNavMap) -> None:
    """A 0.52 m door (the robot fits, its margin does not) and a place to look from in room A that
    the margin reaches: the unseen space beyond the door is still a candidate, weighed at the
    inflation that reaches it (the search of 1dc02c1 weighed every place at the one strictest level
    that reached any, so a kitchen behind a narrow door waited until every other room was looked
    in: s100002-added-0, -2, "the chair that is oak" reached at 24-28 m against a 17-20 m limit)."""
    from capnav.explore.places import Place, room_places
    from capnav.retrieval.query import parse_goals

    walls = [Box((0.6, -3.0, 0.0), (0.75, -0.26, 2.5), 0, 0, (225, 225, 215)),
             Box((0.6, 0.26, 0.0), (0.75, 3.0, 2.5), 0, 0, (225, 225, 215))]
    world = walls + _room_a((-0.3, 2.0))[len(WALLS):]
    agent = BoxAgent(world, -1.2, -0.8, 0.0)
    s = ObjectSearch(first_map, agent, create_detector("sim", noise="oracle", seed=0), Retriever(first_map, _EMB[0]),
                     SearchConfig())  # type: ignore[arg-type]
    s._parsed = parse_goals("the lamp", _EMB[0])[0]  # type: ignore[arg-type]
    s._looked_in = set()
    s.explorer.begin(10**6)
    s.explorer.observe()
    s.explorer.look_around()
    _, regions = room_places(first_map, "lamp", _EMB[0])  # type: ignore[arg-type]
    in_a = Place((-1.8, 0.6), 99, 0.3, "a place in room A")
    out = s._choices([in_a], [], regions)
    cands, dist = out[0], out[1]
    a = [d for c, d in zip(cands, dist, strict=True) if c is in_a]
    assert a and math.isfinite(a[0])
    beyond = [(c, d) for c, d in zip(cands, dist, strict=True) if c.xy[0] > 0.75 and math.isfinite(d)]
    assert beyond, [(c.xy, c.why, d) for c, d in zip(cands, dist, strict=True)]
    levels = out[2]
    assert all(int(levels[list(cands).index(c)]) > 0 for c, _ in beyond)
