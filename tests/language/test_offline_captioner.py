from __future__ import annotations

import numpy as np

from capnav.language import SceneContext, create_captioner
from capnav.language.offline_captioner import ObservationCaptioner, footprint_shape, plural
from capnav.language.prompts import MAX_CAPTION_WORDS, parse_caption

from .synth import grid_with_wall, living_scene, make_obj


def test_captions_follow_the_schema_and_say_what_was_observed():
    objs = living_scene()
    scene = SceneContext(objs, None)
    cap = create_captioner("offline")
    texts = {o.id: cap.caption(o, scene).text for o in objs}
    for t in texts.values():
        assert parse_caption(t) == t
        assert len(t.split(",", 1)[1].split()) <= MAX_CAPTION_WORDS
    assert texts[1].startswith("SOFA, a large red")
    assert "the larger of the two sofas" in texts[1]
    assert "grey" in texts[2] and "the smaller of the two sofas" in texts[2]
    assert "next to the bed" in texts[4]  # the chair beside the bed
    assert "in the bedroom" in texts[4] and "in the kitchen" in texts[5]  # rooms from nearby cues
    assert "2.2 m wide" in texts[1]


def test_category_from_votes_not_the_last_label():
    o = make_obj(1, "chair", (0, 0), (0.9, 0.9, 0.8), (110, 50, 140))
    o.label_votes = {"chair": 1.0, "armchair": 4.0}
    assert ObservationCaptioner().caption(o, SceneContext([o])).text.startswith("ARMCHAIR, a purple armchair")


def test_walls_stop_room_cues():
    """A stove behind a wall does not put the chair in a kitchen, nor through a door into another
    room (rooms are regions of free space); in the same open space it does."""
    chair = make_obj(1, "chair", (2.0, 2.0), (0.5, 0.5, 0.9), (128, 128, 128))
    stove = make_obj(2, "stove", (4.5, 2.0), (0.6, 0.6, 0.9), (190, 192, 196))
    walled = SceneContext([chair, stove], grid_with_wall(0, 0, 7, 5, wall_x=3.3))
    assert walled.room_of(chair) is None and walled.room_of(stove) == "kitchen"
    assert not walled.visible[0, 1]
    door = SceneContext([chair, stove], grid_with_wall(0, 0, 7, 5, wall_x=3.3, door=(1.5, 2.4)))
    assert door.room_of(chair) is None and door.room_of(stove) == "kitchen"
    assert door.region[0] != door.region[1]
    assert SceneContext([chair, stove], grid_with_wall(0, 0, 7, 5)).room_of(chair) == "kitchen"


def test_an_object_against_a_shared_wall_belongs_to_the_room_it_is_reached_from():
    """A cabinet whose mapped box pokes through the wall into the bathroom stays in the office."""
    grid = grid_with_wall(0, 0, 8, 5, wall_x=4.0, door=(3.8, 4.6))
    desk = make_obj(1, "desk", (1.5, 1.0), (1.2, 0.6, 0.75), (120, 80, 40))
    cabinet = make_obj(2, "cabinet", (3.7, 2.0), (0.75, 0.5, 0.9), (240, 240, 236))  # box reaches x = 4.08
    toilet = make_obj(3, "toilet", (5.0, 1.0), (0.4, 0.6, 0.8), (245, 245, 245))
    bathtub = make_obj(4, "bathtub", (6.8, 3.5), (1.6, 0.7, 0.55), (245, 245, 245))
    chair = make_obj(5, "chair", (1.5, 1.6), (0.45, 0.5, 0.9), (120, 80, 40))  # a desk alone is no sure office
    sc = SceneContext([desk, cabinet, toilet, bathtub, chair], grid)
    assert sc.room_of(cabinet) == "office" and sc.room_of(toilet) == "bathroom"


def test_shape_cues():
    rng = np.random.default_rng(0)
    t = rng.uniform(0, 2 * np.pi, 2000)
    r = 0.6 * np.sqrt(rng.uniform(0, 1, 2000))
    disc = make_obj(1, "table", (0, 0), (1.2, 1.2, 0.7), (180, 140, 90))
    disc.points = np.stack([r * np.cos(t), r * np.sin(t), rng.uniform(0, 0.7, 2000)], 1).astype(np.float32)
    assert footprint_shape(disc, ObservationCaptioner().config) == "round"
    xy = rng.uniform(0, 2, (3000, 2))
    ell = xy[(xy[:, 0] < 0.8) | (xy[:, 1] < 0.8)]
    sofa = make_obj(2, "sofa", (1, 1), (2, 2, 0.8), (128, 128, 128))
    sofa.points = np.concatenate([ell, rng.uniform(0, 0.8, (len(ell), 1))], 1).astype(np.float32)
    assert footprint_shape(sofa, ObservationCaptioner().config) == "L-shaped"
    assert plural("bookshelf") == "bookshelves" and plural("chair") == "chairs"


def test_deterministic_and_cache_key_tracks_inputs():
    objs = living_scene()
    scene = SceneContext(objs)
    cap = ObservationCaptioner()
    k1 = cap.cache_key(objs[0], scene)
    assert k1 == cap.cache_key(objs[0], SceneContext(living_scene()))
    objs[0].colors = objs[0].colors[::-1].copy()
    assert cap.cache_key(objs[0], scene) != k1
