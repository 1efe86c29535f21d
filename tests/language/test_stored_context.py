"""Walls, rooms and purpose glosses computed at caption time travel in the map file and are what a
query would compute; a changed map or embedder computes them again."""

from __future__ import annotations

import base64
import copy
import json
from pathlib import Path

import numpy as np
import pytest

from capnav.io.mapfile import load_map, save_map
from capnav.language import SceneContext, create_captioner, create_embedder, describe_map, purpose
from capnav.language import context as ctx
from capnav.mapping.objects import MapObject
from capnav.retrieval import Retriever
from language.synth import grid_with_wall, make_map, make_obj


def two_rooms() -> list[MapObject]:
    # Bedroom left of a wall with a door, kitchen right of it, a chair in each.
    return [make_obj(1, "bed", (1.5, 1.5), (1.6, 2.0, 0.6), (40, 60, 160)),
            make_obj(2, "nightstand", (3.0, 0.5), (0.5, 0.5, 0.6), (120, 80, 40)),
            make_obj(3, "chair", (3.6, 3.4), (0.5, 0.5, 0.9), (200, 40, 40)),
            make_obj(4, "stove", (8.5, 0.5), (0.6, 0.6, 0.9), (30, 30, 32)),
            make_obj(5, "chair", (7.0, 3.4), (0.5, 0.5, 0.9), (200, 40, 40)),
            make_obj(6, "sofa", (7.5, 1.5), (1.8, 0.8, 0.8), (128, 128, 128))]


GRID = grid_with_wall(-0.5, -0.5, 9.5, 4.0, wall_x=5.0, door=(1.0, 2.0))


def same(a: SceneContext, b: SceneContext) -> bool:
    return (np.array_equal(a.visible, b.visible) and np.array_equal(a.room_score, b.room_score)
            and np.array_equal(a.region, b.region) and a.region_rooms == b.region_rooms and a.rooms == b.rooms)


def test_stored_walls_and_rooms_round_trip_and_are_read(tmp_path: Path) -> None:
    objs = two_rooms()
    cmap = make_map(objs, GRID)
    fresh = SceneContext(objs, GRID)
    assert fresh.region.max() >= 1 and not fresh.visible.all()  # two regions, a wall between objects
    store = cmap.caches.setdefault(ctx.CACHE_KEY, {})
    assert same(SceneContext(objs, GRID, store=store), fresh) and store["digest"]
    back = load_map(save_map(cmap, tmp_path / "m.capnav"))
    assert same(SceneContext(back.objects, back.occupancy, store=back.caches[ctx.CACHE_KEY]), fresh)
    # What is stored is what is used (a tampered score with the right digest shows through) ...
    tampered = copy.deepcopy(back.caches[ctx.CACHE_KEY])
    tampered["room_score"][0][0] = 0.123
    assert SceneContext(back.objects, back.occupancy, store=tampered).room_score[0, 0] == 0.123
    # ... and a malformed entry is computed again.
    broken = {**tampered, "room_score": [[0.5]]}
    assert same(SceneContext(back.objects, back.occupancy, store=broken), fresh)


def test_a_changed_map_recomputes_and_replaces_the_stored_context() -> None:
    objs = two_rooms()
    store: dict = {}
    SceneContext(objs, GRID, store=store)
    old = store["digest"]
    moved = two_rooms()
    moved[4] = make_obj(5, "chair", (2.0, 3.4), (0.5, 0.5, 0.9), (200, 40, 40))  # into the bedroom
    sc = SceneContext(moved, GRID, store=store)
    assert same(sc, SceneContext(moved, GRID)) and sc.rooms[4] == "bedroom"
    assert store["digest"] != old
    open_plan = grid_with_wall(-0.5, -0.5, 9.5, 4.0)  # the same objects without the wall
    sc = SceneContext(moved, open_plan, store=store)
    assert same(sc, SceneContext(moved, open_plan))


@pytest.fixture(scope="module")
def emb():  # type: ignore[no-untyped-def]
    return create_embedder("minilm")


def test_stored_glosses_are_the_computed_ones_and_follow_the_embedder(emb) -> None:  # type: ignore[no-untyped-def]
    computed = purpose.GlossIndex(emb)
    stored = json.loads(json.dumps(computed.to_store()))
    assert np.array_equal(purpose.GlossIndex(emb, stored=stored).E, computed.E)
    def zero(block):  # type: ignore[no-untyped-def]
        return {**block, "float32_le": base64.b64encode(np.zeros(block["shape"], "<f4").tobytes()).decode()}

    zeros = {**zero(stored), "stated": zero(stored["stated"])}
    assert not purpose.GlossIndex(emb, stored=zeros).E.any()  # the stored vectors are the ones used
    # Another model, other gloss texts or a truncated payload: embedded again (the gloss block).
    n = computed.n_glosses
    for bad in ({**zeros, "digest": "0" * 64}, {**zeros, "float32_le": zeros["float32_le"][:100]}):
        assert np.array_equal(purpose.GlossIndex(emb, stored=bad).E[:n], computed.E[:n])
    assert np.array_equal(purpose.GlossIndex(emb, max_glosses=2, stored=zeros).E,
                          purpose.GlossIndex(emb, max_glosses=2).E)


def test_a_captioned_map_answers_as_without_its_stored_context(emb, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    """describe_map stores walls, rooms and glosses; the saved map answers exactly as the same map
    with them removed (computed at query time, as for maps captioned before they were stored)."""
    cmap = make_map(two_rooms(), GRID)
    describe_map(cmap, None, create_captioner("offline"), emb, progress=False)
    assert {ctx.CACHE_KEY, purpose.CACHE_KEY} <= set(cmap.caches)
    path = save_map(cmap, tmp_path / "m.capnav")
    bare = load_map(path, voxels=False)
    for key in (ctx.CACHE_KEY, purpose.CACHE_KEY):
        del bare.caches[key]
    texts = ["the red chair in the kitchen", "the chair next to the bed", "somewhere to sit",
             "where can I take a nap", "the chair closest to the stove"]
    stored = Retriever(load_map(path, voxels=False), create_embedder("minilm"))
    computed = Retriever(bare, create_embedder("minilm"))
    for text in texts:
        a, b = stored.query(text).to_dict(), computed.query(text).to_dict()
        a.pop("timings"), b.pop("timings")
        assert a == b, text
