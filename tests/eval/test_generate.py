"""Episode generation on a hand-built apartment truth (no simulator needed)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from capnav.core.errors import DatasetError
from capnav.core.grid import GridSpec
from capnav.eval.generate import EpisodeConfig, SceneTruth, description_episodes, label_episodes


def box(x: float, y: float, s: float = 0.4) -> np.ndarray:
    return np.array([[x, y], [x + s, y], [x + s, y + s], [x, y + s]])


def truth() -> SceneTruth:
    spec = GridSpec(0.0, 0.0, 0.1, 80, 80)
    nav = np.ones((80, 80), dtype=bool)
    cats = {1: "sofa", 2: "sofa", 3: "chair", 4: "chair", 5: "tv", 6: "bed"}
    fps = {1: box(1, 1), 2: box(6, 6), 3: box(1, 6), 4: box(3, 3), 5: box(6, 1), 6: box(4, 7)}
    for f in fps.values():  # objects are not navigable
        rc = spec.to_cell(f)
        nav[rc[:, 0].min(): rc[:, 0].max() + 1, rc[:, 1].min(): rc[:, 1].max() + 1] = False
    return SceneTruth(7, cats, fps, spec, nav)


def test_label_episodes_are_valid_and_seeded() -> None:
    t = truth()
    a = label_episodes(t, np.random.default_rng(3), EpisodeConfig(episodes_per_scene=5))
    b = label_episodes(truth(), np.random.default_rng(3), EpisodeConfig(episodes_per_scene=5))
    assert [e.model_dump() for e in a] == [e.model_dump() for e in b]
    for e in a:
        cats = [g.category for g in e.subgoals]
        assert len(cats) == 4 and len(set(cats)) == 4  # 4 categories present: no repeats
        for g in e.subgoals:
            assert g.text == g.category and g.target_ids == t.instances_of(g.category)
        assert t.navigable[tuple(t.spec.to_cell(np.array([e.start.x, e.start.y])))]
        assert t.field(e.subgoals[0].target_ids).at((e.start.x, e.start.y)) >= 1.0


def test_description_episodes_prefer_lookalikes() -> None:
    t = truth()

    def describe(i: int, robot_xy: tuple[float, float] | None, rng: np.random.Generator) -> tuple[str, str]:
        where = " (closest)" if robot_xy is not None else ""
        # chair 4 cannot be singled out: the describer falls back to its bare category
        return (f"the {t.categories[i]}", "category") if i == 4 else (f"the {t.categories[i]} {i}{where}", "attribute")

    eps = description_episodes(t, describe, np.random.default_rng(0), EpisodeConfig(episodes_per_scene=3,
                                                                                      subgoals=3))
    for e in eps:
        ids = [g.target_ids[0] for g in e.subgoals]
        assert set(ids) <= {1, 2, 3}  # only lookalikes (sofa 1, 2; chair 3, 4), and never the undescribable 4
        assert len(set(ids)) == 3
        cats = [t.categories[i] for i in ids]
        assert all(a != b for a, b in itertools.pairwise(cats))
        # the robot position is given for the first subgoal only (where "closest" is well defined)
        assert [g.text.endswith("(closest)") for g in e.subgoals] == [True, False, False]
        assert all(g.kind == "attribute" for g in e.subgoals)


def test_unreachable_scene_is_a_clear_error() -> None:
    t = truth()
    t.navigable[:] = False
    t.navigable[0, 0] = True
    with pytest.raises(DatasetError, match="no valid label episode"):
        label_episodes(t, np.random.default_rng(0), EpisodeConfig(episodes_per_scene=1, max_tries=5))


def test_starts_keep_the_planners_margin_and_a_way_out() -> None:
    from capnav.sim.navgrid import start_cells

    # A 2 m room (clearance grows from its walls) with a pocket joined to it by a neck whose
    # clearance is the robot's radius only: the pocket is navigable but no start is drawn there.
    clearance = np.zeros((40, 80))
    rr, cc = np.mgrid[0:40, 0:80]
    room = (cc < 40) & (rr > 0) & (rr < 39) & (cc > 0)
    clearance[room] = np.minimum.reduce([rr[room], 39 - rr[room], cc[room], 40 - cc[room]]) * 0.05
    pocket = (cc > 45) & (cc < 70) & (rr > 10) & (rr < 30)
    clearance[pocket] = 0.6
    neck = (cc >= 40) & (cc <= 45) & (rr >= 18) & (rr <= 21)
    clearance[neck] = 0.21
    inside = clearance > 0.2
    ok = start_cells(clearance, inside, 0.3)
    assert ok[20, 20] and not ok[20, 60] and not ok[2, 20]  # the room's middle; not the pocket, not by a wall
    assert (clearance[ok] > 0.3).all()


def test_strict_in_the_objects_room_needs_the_stop_in_its_room() -> None:
    from capnav.sim.sightline import SightGrid

    spec = GridSpec(0.0, 0.0, 0.1, 40, 80)
    truth = SceneTruth(0, {1: "sofa"}, {1: np.array([[3.3, 1.0], [3.8, 1.0], [3.8, 1.5], [3.3, 1.5]])}, spec,
                       np.ones((40, 80), bool), sight=SightGrid(spec, np.zeros((40, 80), np.int32)),
                       rooms=[np.array([[0, 0], [3, 0], [3, 4], [0, 4]], float),
                              np.array([[3, 0], [8, 0], [8, 4], [3, 4]], float)])
    assert truth.room_of((1.0, 1.0)) == 0 and truth.room_of((5.0, 1.0)) == 1 and truth.room_of((9.0, 1.0)) == -1
    assert truth.in_goal_room((3.9, 1.2), [1]) is True
    assert truth.in_goal_room((2.8, 1.2), [1]) is False  # within 1 m and in sight (no wall drawn) but next door
    assert truth.sees_goal((2.8, 1.2), [1]) is True


def _walled_truth() -> SceneTruth:
    """Two rooms split by a wall at x = 3 m with a door at its top (y > 3.5 m); a sofa just past it."""
    from capnav.sim.sightline import WALL, SightGrid

    spec = GridSpec(0.0, 0.0, 0.1, 40, 80)
    labels = np.zeros((40, 80), np.int32)
    labels[:35, 30] = WALL
    nav = labels == 0
    return SceneTruth(0, {1: "sofa"}, {1: np.array([[3.3, 1.0], [3.8, 1.0], [3.8, 1.5], [3.3, 1.5]])}, spec,
                      nav, sight=SightGrid(spec, labels))


def test_the_walk_to_a_viewpoint_goes_round_the_wall_the_1m_region_reaches_through() -> None:
    truth = _walled_truth()
    start = (2.5, 1.2)  # 0.8 m from the sofa, behind the wall
    assert truth.field([1]).at(start) == 0.0  # the plain 1 m region holds the start
    view = truth.view_field([1])
    assert view is not None
    assert 3.0 < view.at(start) < 8.0  # up to the door, through it and back down to see the sofa
    assert view.at((4.5, 1.2)) == 0.0  # in the sofa's room, within 1 m: a viewpoint


def test_a_search_budget_is_three_walks_to_the_nearest_viewpoint() -> None:
    from capnav.eval.change_track import _within_budget
    from capnav.eval.metrics import SubgoalRecord

    truth = _walled_truth()

    def record(driven: float) -> SubgoalRecord:
        return SubgoalRecord("capnav-search", "description/moved", 0, "e", 0, "the sofa", "sofa", [1], "name",
                             True, 0.5, driven, truth.field([1]).at((2.5, 1.2)), (2.5, 1.2), (3.5, 0.6),
                             True, True, 0.0, 1, reason="reached")

    r = record(9.0)  # round through the door: within 3x (walk to the viewpoint + 1 m), over 3x of 1 m
    _within_budget(r, truth)
    assert r.success and r.view_path is not None and r.view_path > 3.0
    r = record(40.0)
    _within_budget(r, truth)
    assert not r.success and r.reason.startswith("reached, but drove 40.0 m")
