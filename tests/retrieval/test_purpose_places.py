"""Purposes of putting something down ask for a surface (WordNet's placing verbs: put, set, rest,
lay, plonk ...; the surfaces are the table and its kinds in the lexicon), not for whatever the
thing put down is kept in; a landmark said between the place word and the activity ("a spot by
the bed to ...") or by what is done at it ("next to where I sleep") decides among the surfaces.
Sentences and the scene are written for these tests (none from a development set)."""

from __future__ import annotations

import pytest

from capnav.language.purpose import is_placing
from capnav.retrieval import Retriever
from language.synth import grid_with_wall, make_obj, offline_retriever

NIGHTSTAND, COFFEE_TABLE, DESK = 3, 7, 10
SURFACES = {"table", "coffee table", "nightstand", "desk", "counter"}


@pytest.fixture(scope="module")
def retriever() -> Retriever:
    objs = [
        make_obj(1, "bed", (6.5, 3.0), (1.6, 2.0, 0.5), (200, 200, 230)),
        make_obj(2, "wardrobe", (8.4, 6.2), (1.0, 0.6, 2.0), (120, 90, 60)),
        make_obj(NIGHTSTAND, "nightstand", (7.6, 1.6), (0.45, 0.4, 0.55), (150, 110, 70)),
        make_obj(4, "dresser", (5.0, 6.3), (1.0, 0.5, 0.9), (150, 110, 70)),
        make_obj(5, "bookshelf", (3.0, 6.4), (0.9, 0.35, 1.8), (90, 60, 40)),
        make_obj(6, "sofa", (1.0, 1.0), (2.0, 0.9, 0.8), (60, 60, 140)),
        make_obj(COFFEE_TABLE, "coffee table", (1.0, 2.1), (1.0, 0.6, 0.45), (120, 80, 50)),
        make_obj(8, "tv", (1.0, 6.4), (1.2, 0.3, 0.7), (20, 20, 20)),
        make_obj(9, "armchair", (2.8, 2.0), (0.8, 0.8, 0.9), (170, 50, 50)),
        make_obj(DESK, "desk", (3.2, 4.2), (1.2, 0.6, 0.75), (90, 60, 40)),
    ]
    return offline_retriever(objs, grid_with_wall(-1, -1, 9, 7))


@pytest.mark.parametrize(("activity", "placing"), [
    ("rest my cup of cocoa", True), ("set down a book", True), ("plonk my keys", True),
    ("put my reading glasses down", True), ("put my jumpers away", False), ("put the milk in", False),
    ("keep my shoes", False), ("sleep", False),
])
def test_placing_verbs_come_from_the_lexicon(activity: str, placing: bool) -> None:
    assert is_placing(activity) is placing


@pytest.mark.parametrize(("text", "oid"), [
    ("I want somewhere right beside the bed to rest my cup of cocoa", NIGHTSTAND),
    ("is there anywhere near the sofa where I can set down a book", COFFEE_TABLE),
    ("where could I put my reading glasses down next to where I sleep", NIGHTSTAND),
])
def test_a_landmark_decides_among_the_surfaces(retriever: Retriever, text: str, oid: int) -> None:
    res = retriever.query(text)
    assert res.found and res.chosen is not None and res.chosen.id == oid, res.reason


def test_putting_something_down_asks_for_a_surface(retriever: Retriever) -> None:
    for text in ("somewhere to plonk my keys", "where can I lay my magazines for a bit"):
        res = retriever.query(text)
        assert res.found and res.chosen is not None and res.chosen.label in SURFACES, (text, res.reason)
