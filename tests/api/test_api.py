"""The library face (``capnav.api``) on a small captioned synthetic map: typed records, answers
with reason, runners-up and goal pose, plans, lazy construction and bad input."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from capnav.api import Answer, CapNav, ObjectRecord, Plan
from capnav.core.errors import InputError
from capnav.core.grid import FREE, OCCUPIED, UNKNOWN
from capnav.mapping.cmap import CapNavMap
from language.synth import described_living_map, grid_with_wall, living_scene, make_map, walked_through_the_door


@pytest.fixture(scope="module")
def map_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return described_living_map(tmp_path_factory.mktemp("api"))


def test_constructing_does_no_work(map_file: Path) -> None:
    nav = CapNav.open(map_file)
    assert nav._embedder is None and nav._retriever is None and nav._costmap is None
    assert "7 objects" in repr(nav)


def test_objects_are_typed_records(map_file: Path) -> None:
    nav = CapNav.open(map_file)
    objs = nav.objects()
    assert [o.id for o in objs] == [1, 2, 3, 4, 5, 6, 7]
    sofa = nav.object(1)
    assert isinstance(sofa, ObjectRecord) and sofa.category == "sofa" and sofa.caption.startswith("SOFA")
    assert sofa.min == pytest.approx((-0.1, 0.55, 0.0)) and sofa.max == pytest.approx((2.1, 1.45, 0.8))
    assert sofa.centroid == pytest.approx((1.0, 1.0, 0.4))
    assert sofa.embedding is not None and np.linalg.norm(sofa.embedding) == pytest.approx(1.0, abs=1e-5)
    d = sofa.to_dict()
    assert d["id"] == 1 and "embedding" not in d and d["max"] == [2.1, 1.45, 0.8]


def test_ask_gives_reason_runners_up_and_goal(map_file: Path) -> None:
    nav = CapNav.open(map_file)
    ans = nav.ask("the red sofa", robot=(6.0, 3.0))
    assert isinstance(ans, Answer) and ans.found and ans.object is not None and ans.object.id == 1
    assert "Chose object 1" in ans.reason and ans.score > 0.3
    assert ans.runners_up and all(o.id != 1 for o, _ in ans.runners_up)
    assert ans.goal is not None and ans.goal.reached_within_reach and ans.goal_note == ""
    # the goal is free, within reach of the sofa, and on the robot's side of the wall's door
    assert ans.goal.distance_to_object <= 1.0
    closest = nav.ask("the closest chair", robot=(6.0, 3.0), k=1)
    assert closest.object is not None and closest.object.id == 4 and len(closest.runners_up) <= 1
    no_robot = nav.ask("the red sofa")
    assert no_robot.goal is None and "no robot position" in no_robot.goal_note
    inside = nav.ask("the red sofa", robot=(3.8, 6.0))  # in the wall: the answer stands, without a goal
    assert inside.object is not None and inside.goal is None and "obstacle" in inside.goal_note
    missing = nav.ask("the piano")
    assert not missing.found and missing.object is None and missing.reason.startswith("Not found")
    assert missing.to_dict()["object"] is None


def test_plan_to_an_answer(map_file: Path) -> None:
    nav = CapNav.open(map_file)
    ans = nav.ask("the red sofa", robot=(6.0, 3.0))
    plan = nav.plan((6.0, 3.0, 0.5), ans)
    assert isinstance(plan, Plan) and plan.success and plan.target == 1
    assert plan.poses.shape[1] == 3 and plan.poses[0] == pytest.approx([6.0, 3.0, 0.5])
    assert plan.poses[-1, :2] == pytest.approx(plan.goal.xy) and plan.poses[-1, 2] == pytest.approx(plan.goal.yaw)
    # it goes through the door (2.5 < y < 3.5) at the wall x = 3.8
    seg = np.linspace(plan.poses[:-1, :2], plan.poses[1:, :2], 50).reshape(-1, 2)
    crossing = seg[np.abs(seg[:, 0] - 3.8) < 0.03]
    assert len(crossing) and (crossing[:, 1] > 2.5).all() and (crossing[:, 1] < 3.5).all()
    steps = np.linalg.norm(np.diff(plan.poses[:, :2], axis=0), axis=1).sum()
    assert plan.length_m == pytest.approx(steps, abs=1e-6) and "A* path" in plan.reason
    assert nav.plan((6.0, 3.0), 7).success and nav.plan((6.0, 3.0), nav.object(3)).target == 3
    nothing = nav.plan((6.0, 3.0), nav.ask("the piano"))
    assert not nothing.success and "nothing to plan to" in nothing.reason


def test_plan_failure_is_a_result_and_bad_input_raises(map_file: Path) -> None:
    from capnav.io.mapfile import load_map

    cmap = load_map(map_file)
    cmap.occupancy = grid_with_wall(-1, -1, 9, 7, wall_x=3.8)  # no door: the left half is cut off
    nav = CapNav(cmap)
    plan = nav.plan((6.0, 3.0), 1)  # it gets as close as it can, and says it is not there
    assert not plan.success and "no reachable free cell within 1.00 m" in plan.reason
    assert plan.goal is not None and plan.poses[-1, 0] > 3.8
    with pytest.raises(InputError, match="x, y"):
        nav.ask("the red sofa", robot=("a", 1))
    with pytest.raises(InputError, match="k must"):
        nav.ask("the red sofa", k=-1)
    with pytest.raises(InputError, match="obstacle"):
        nav.plan((3.8, 6.0), 1)
    with pytest.raises(InputError, match="CapNavMap"):
        CapNav("map.capnav")  # type: ignore[arg-type]


def test_uncaptioned_map_says_what_to_do(tmp_path: Path) -> None:
    nav = CapNav(make_map(living_scene()))
    with pytest.raises(InputError, match="caption it first"):
        nav.ask("the red sofa")
    rep = nav.caption()  # no frames: keeps (no) views, captions from what the map observed
    assert rep.objects == 7 and nav.ask("the red sofa").object.id == 1


def test_plans_like_navigate_from_the_camera_path(map_file: Path) -> None:
    """``plan`` starts where ``capnav navigate`` does (the last camera pose) and plans on the same
    grid (unknown cells near the camera path free): with unknown space blocked, the door the camera
    walked through is the only way to the sofa."""
    from capnav.planning.config import PlannerConfig
    from capnav.planning.on_map import camera_yaw, navigate_on_map

    cmap = walked_through_the_door(map_file)
    cfg = PlannerConfig(unknown_cost=None)
    nav = CapNav(cmap, planner=cfg)
    (x, y, yaw), source = nav.start_pose()
    last = cmap.trajectory.poses[-1]  # type: ignore[union-attr]
    assert (x, y, yaw) == pytest.approx((6.0, 3.0, camera_yaw(last))) and source == "the last camera pose (frame 30)"
    assert (nav.occupancy.cells[cmap.occupancy.cells == UNKNOWN] == FREE).any()  # the door, crossed
    np.testing.assert_array_equal(nav.occupancy.cells == OCCUPIED, cmap.occupancy.cells == OCCUPIED)
    plan = nav.plan(None, 1)
    assert plan.success, plan.reason
    assert plan.poses[0] == pytest.approx([6.0, 3.0, yaw])
    ref = navigate_on_map(cmap, nav.retriever, "the red sofa", config=cfg)
    assert ref.ok and ref.query.chosen is not None and ref.query.chosen.id == 1 and ref.path is not None
    np.testing.assert_array_equal(nav.occupancy.cells, ref.occupancy.cells)
    np.testing.assert_allclose(plan.poses[:, :2], ref.path.waypoints)
    assert plan.length_m == pytest.approx(ref.path.length_m)
    ans = nav.ask("the red sofa", robot=(x, y))
    assert ans.goal is not None and ans.goal.xy == pytest.approx(ref.goal.xy)  # type: ignore[union-attr]
    # the mapped grid alone has no way through: the same start is cut off from the sofa
    blind = CapNav(CapNavMap(cmap.objects, cmap.voxels, cmap.occupancy, cmap.meta, cmap.caches, trajectory=None),
                   planner=cfg)
    assert not blind.plan((6.0, 3.0), 1).success
    with pytest.raises(InputError, match="records no camera path"):
        blind.plan(None, 1)


def test_open_without_voxels_answers_alike_and_refuses_to_save(map_file: Path, tmp_path: Path) -> None:
    """The fast path for a process that asks once: same answers and goals, no voxel map to lose."""
    full, light = CapNav.open(map_file), CapNav.open(map_file, voxels=False)
    assert len(light.map.voxels) == 0
    for text in ("the red sofa", "the closest chair", "the piano"):
        a, b = full.ask(text, robot=(6.0, 3.0)).to_dict(), light.ask(text, robot=(6.0, 3.0)).to_dict()
        a.pop("timings_ms"), b.pop("timings_ms")
        assert a == b
    with pytest.raises(InputError, match="voxels=False"):
        light.save(tmp_path / "copy.capnav")
    assert not (tmp_path / "copy.capnav").exists()
    assert full.save(tmp_path / "copy.capnav").is_file()
