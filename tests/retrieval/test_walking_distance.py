"""'Closest' ranks by the walk along the floor, not by the straight line through a wall: a scene
where the two orders differ (a plant just behind a wall whose door is far away, another farther
off in the robot's own room), for the robot and for a landmark. Sentences written for this scene."""

from __future__ import annotations

import numpy as np
import pytest

from capnav.core.errors import InputError
from capnav.language import create_embedder
from capnav.retrieval import RetrievalConfig, Retriever
from capnav.retrieval.spatial import FloorDistances
from language.synth import captioned_map, grid_with_wall, make_obj

ROBOT = (4.0, 1.0)


@pytest.fixture(scope="module")
def scene():
    emb = create_embedder("minilm")
    objs = [
        make_obj(1, "potted plant", (5.8, 1.0), (0.4, 0.4, 0.8), (40, 140, 60)),  # 1.8 m away, behind the wall
        make_obj(2, "potted plant", (1.0, 3.0), (0.4, 0.4, 0.8), (40, 140, 60)),  # 3.6 m away, same room
        make_obj(3, "sofa", (3.0, 4.5), (2.0, 0.9, 0.8), (30, 30, 140)),
        make_obj(4, "armchair", (4.2, 2.2), (0.8, 0.8, 0.9), (150, 40, 40)),  # by the wall, the robot's side
    ]
    grid = grid_with_wall(-0.5, -0.5, 9.5, 6.5, wall_x=5.0, door=(5.2, 6.2))  # the door at the far north end
    cmap = captioned_map(objs, emb, grid)
    return cmap, emb


def test_the_nearest_plant_is_the_one_the_robot_walks_to_first(scene) -> None:
    cmap, emb = scene
    walk = Retriever(cmap, emb).query("the nearest plant to me", robot_xy=ROBOT)
    assert walk.found and walk.chosen.id == 2
    assert "walking along the floor" in walk.reason
    straight = Retriever(cmap, emb, config=RetrievalConfig(distance="straight")).query(
        "the nearest plant to me", robot_xy=ROBOT)
    assert straight.found and straight.chosen.id == 1 and "straight line" in straight.reason
    # and "farthest" reverses the walk, not the line
    far = Retriever(cmap, emb).query("the farthest plant from me", robot_xy=ROBOT)
    assert far.chosen.id == 1


def test_walking_distances_go_round_the_wall(scene) -> None:
    cmap, _ = scene
    los = np.array([o.extent_min[:2] for o in cmap.objects])
    his = np.array([o.extent_max[:2] for o in cmap.objects])
    floor = FloorDistances(cmap.occupancy, los, his)
    d = floor.from_point(ROBOT)
    line = np.array([np.hypot(*(o.position[:2] - ROBOT)) for o in cmap.objects])
    assert d[0] > line[0] + 5.0  # up to the door at y 5.2 and back down: > 7 m, not 1.6 m
    assert d[1] == pytest.approx(line[1] - 0.2, abs=0.5)  # straight across the open room
    assert floor.from_point(ROBOT) is d  # one Dijkstra per robot cell


def test_a_landmark_relative_superlative_walks_too(scene) -> None:
    cmap, emb = scene
    # The armchair stands by the wall: plant 1 is 1.9 m from it through the wall, plant 2 3.3 m
    # across the open room; a walk from the armchair reaches plant 2 first.
    res = Retriever(cmap, emb).query("the plant closest to the armchair")
    assert res.found and res.chosen.id == 2
    res = Retriever(cmap, emb, config=RetrievalConfig(distance="straight")).query("the plant closest to the armchair")
    assert res.found and res.chosen.id == 1


def test_an_unknown_distance_kind_is_refused() -> None:
    with pytest.raises(InputError, match="walking' or 'straight"):
        RetrievalConfig(distance="euclid")


def test_no_cache_walks_again_and_a_negative_size_is_refused(scene) -> None:
    cmap, _ = scene
    los = np.array([o.extent_min[:2] for o in cmap.objects])
    his = np.array([o.extent_max[:2] for o in cmap.objects])
    uncached = FloorDistances(cmap.occupancy, los, his, cache_size=0)
    a, b = uncached.from_point(ROBOT), uncached.from_point(ROBOT)
    assert a is not b and np.array_equal(a, b)
    with pytest.raises(InputError, match="cache_size must be >= 0"):
        FloorDistances(cmap.occupancy, los, his, cache_size=-1)


def test_rankings_read_off_walk_fields_are_those_of_the_walks(scene) -> None:
    # Every object's walk field made ahead (as a server does at load): "closest" and "farthest"
    # from robots no walk started from give the answers, reasons and distances of the walks.
    cmap, emb = scene
    fields, walks = Retriever(cmap, emb), Retriever(cmap, emb)
    walks.field_bytes = 0
    floor = fields.floor_distances()
    assert floor is not None and floor.prepare() == len(cmap.objects)
    rng = np.random.default_rng(4)
    for text in ("the nearest plant to me", "the farthest plant from me", "the closest seat", "the plant"):
        for _ in range(6):
            robot = (float(rng.uniform(0.0, 9.0)), float(rng.uniform(0.0, 6.0)))
            a, b = fields.query(text, robot_xy=robot), walks.query(text, robot_xy=robot)
            assert (a.chosen.id if a.chosen else None) == (b.chosen.id if b.chosen else None)
            assert a.reason == b.reason and a.distance_m == b.distance_m and a.details == b.details
            assert [o.id for o, _ in a.ranked] == [o.id for o, _ in b.ranked]
    assert floor.held > 0 and walks.floor_distances().held == 0
