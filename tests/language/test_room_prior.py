"""Rooms from evidence, said only when sure: a region's room type is the posterior of what stands
in it; a sink alone is no room, a sink with a stove a kitchen, with a toilet a bathroom."""

from __future__ import annotations

import pytest

from capnav.language import SceneContext, create_captioner
from capnav.language.room_prior import ROOM_PRIOR, best_room, room_posterior

from .synth import grid_with_wall, make_obj


def test_posterior_from_what_stands_in_a_region() -> None:
    assert best_room(["sink"], 0.8)[0] is None  # kitchen or bathroom: not sure
    assert best_room(["sink", "stove"], 0.8)[0] == "kitchen"
    assert best_room(["sink", "refrigerator", "chair"], 0.8)[0] == "kitchen"
    assert best_room(["sink", "toilet"], 0.8)[0] == "bathroom"
    assert best_room(["sink", "bathtub"], 0.8)[0] == "bathroom"
    assert best_room(["table", "chair", "chair"], 0.8)[0] is None  # a dining table stands in several rooms
    assert best_room(["plant", "lamp"], 0.8) == (None, 0.0)  # no evidence at all
    post = room_posterior(["bed", "tv"])
    assert sum(post.values()) == pytest.approx(1.0) and max(post, key=post.__getitem__) == "bedroom"
    assert set(ROOM_PRIOR) >= {"kitchen", "bathroom", "bedroom", "living room", "office"}


def test_a_region_with_only_a_sink_is_no_room_and_its_caption_names_none() -> None:
    """Two rooms behind a wall with a door: a sink alone on the left, a sink and a toilet on the
    right. The left sink used to be called 'in the bathroom' from its own cue."""
    grid = grid_with_wall(0, 0, 8, 5, wall_x=4.0, door=(3.8, 4.6))
    lone = make_obj(1, "sink", (1.0, 1.0), (0.6, 0.46, 0.85), (240, 240, 240))
    sink = make_obj(2, "sink", (5.0, 1.0), (0.6, 0.46, 0.85), (240, 240, 240))
    toilet = make_obj(3, "toilet", (6.5, 1.0), (0.4, 0.6, 0.8), (245, 245, 245))
    stove = make_obj(4, "stove", (2.5, 4.0), (0.6, 0.6, 0.9), (30, 30, 30))
    sc = SceneContext([lone, sink, toilet], grid)
    assert sc.region[0] != sc.region[1]
    assert sc.room_of(lone) is None and sc.room_of(sink) == "bathroom" and sc.room_of(toilet) == "bathroom"
    text = create_captioner("offline").caption(lone, sc).text
    assert "bathroom" not in text and "kitchen" not in text
    with_stove = SceneContext([lone, sink, toilet, stove], grid)  # a stove beside it: a kitchen sink
    assert with_stove.room_of(lone) == "kitchen" and with_stove.room_of(sink) == "bathroom"
