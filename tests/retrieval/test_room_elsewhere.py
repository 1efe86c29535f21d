"""A room is evidence against a candidate when the map has that room elsewhere: "the kitchen
stool" is not the stool of the hallway when a region of the map is the kitchen, while a map with
no region typed kitchen cannot tell (the room is unobserved, and the stool may answer). A scene
written for these tests: a kitchen (x < 4), a hallway (4 < x < 6) and a bedroom (x > 6)."""

from __future__ import annotations

import pytest

from capnav.retrieval import Retriever
from language.synth import grid_with_walls, make_obj, offline_retriever


def _retriever(objs: list) -> Retriever:  # type: ignore[type-arg]
    return offline_retriever(objs, grid_with_walls(-1, -1, 10, 7, [(4.0, (2.5, 3.5)), (6.0, (2.5, 3.5))]))


@pytest.fixture(scope="module")
def three_rooms() -> Retriever:
    return _retriever([
        make_obj(1, "stove", (0.6, 6.2), (0.7, 0.6, 0.9), (40, 40, 40)),
        make_obj(2, "refrigerator", (2.0, 6.3), (0.7, 0.7, 1.8), (235, 235, 235)),
        make_obj(3, "counter", (0.5, 3.5), (0.6, 2.0, 0.9), (150, 120, 90)),
        make_obj(4, "stool", (5.0, 5.5), (0.4, 0.4, 0.7), (90, 60, 40)),  # in the hallway
        make_obj(5, "bed", (8.0, 3.0), (1.6, 2.0, 0.5), (200, 200, 230)),
        make_obj(6, "nightstand", (9.3, 1.5), (0.45, 0.4, 0.55), (150, 110, 70)),
    ])


def test_a_named_room_the_map_has_elsewhere_refuses(three_rooms: Retriever) -> None:
    kitchen = {three_rooms.scene.rooms[k] for k, o in enumerate(three_rooms.objects) if o.id in (1, 2, 3)}
    assert kitchen == {"kitchen"}, kitchen
    res = three_rooms.query("the little kitchen stool")
    assert not res.found, res.reason
    res = three_rooms.query("the little stool")
    assert res.found and res.chosen is not None and res.chosen.id == 4, res.reason


def test_a_room_the_map_never_typed_is_unobserved() -> None:
    r = _retriever([make_obj(4, "stool", (5.0, 5.5), (0.4, 0.4, 0.7), (90, 60, 40)),
                    make_obj(7, "lamp", (8.0, 1.0), (0.4, 0.4, 1.5), (230, 230, 200))])
    assert "kitchen" not in {room for room, _ in r.scene.region_rooms.values()}
    res = r.query("the little kitchen stool")
    assert res.found and res.chosen is not None and res.chosen.id == 4, res.reason
