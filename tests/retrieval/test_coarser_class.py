"""A COCO detector has one "chair" class for armchairs and dining chairs and one "dining table"
class for every table: a map made with it holds an armchair as a chair and a coffee table as a
table. "The armchair" or "the coffee table" asked of such a map was refused ("the detector has
no armchair class") with the armchair standing there as a chair (a simulated recording mapped
with CenterNet, 2026-12-04). A named category that the map's detector has no class for, but that
is a kind of a class it has (in the lexicon), is looked for among that class's objects, said so
in the reason; a category that is no kind of any of its classes (a wardrobe) is still refused
for that reason, and a map whose detector could name the category keeps the stand-in rule (a
chair is no armchair there). Scenes and sentences written for this test."""

from __future__ import annotations

import pytest

from capnav.language import create_embedder
from capnav.retrieval import Retriever
from language.synth import captioned_map, grid_with_wall, make_obj

COCO = {"detector": "test-coco:classes=indoor",
        "detector_labels": sorted({"chair", "sofa", "bed", "table", "tv", "plant", "toilet", "sink",
                                   "refrigerator", "stove", "vase", "book", "bench"})}
WIDE_CHAIR, DINING_CHAIR, LOW_TABLE, BED = 1, 2, 3, 4


@pytest.fixture(scope="module")
def emb():
    return create_embedder("minilm")


def _lounge(emb, meta):
    cmap = captioned_map([
        make_obj(WIDE_CHAIR, "chair", (1.0, 1.0), (0.9, 0.9, 0.9), (30, 30, 30)),
        make_obj(DINING_CHAIR, "chair", (6.0, 5.0), (0.45, 0.5, 0.9), (200, 30, 30)),
        make_obj(LOW_TABLE, "table", (2.5, 1.5), (1.0, 0.6, 0.45), (150, 100, 60)),
        make_obj(BED, "bed", (6.0, 1.5), (1.6, 2.0, 0.5), (220, 220, 220)),
    ], emb, grid_with_wall(-0.5, -0.5, 9.0, 7.0))
    cmap.meta.update(meta)
    return Retriever(cmap, emb)


@pytest.fixture(scope="module")
def coco(emb) -> Retriever:
    return _lounge(emb, COCO)


@pytest.mark.parametrize(("text", "want"), [
    ("the armchair", {WIDE_CHAIR, DINING_CHAIR}),
    ("the black armchair", {WIDE_CHAIR}),
    ("take me to the coffee table", {LOW_TABLE}),
])
def test_a_kind_of_a_detector_class_is_looked_for_among_that_class(coco: Retriever, text: str, want: set[int]) -> None:
    res = coco.query(text)
    assert res.found and res.chosen is not None and res.chosen.id in want, res.reason
    assert "detector" in res.reason, res.reason  # it says why a chair may be the armchair


def test_no_kind_of_any_class_is_still_refused_for_that_reason(coco: Retriever) -> None:
    res = coco.query("the wardrobe")
    assert not res.found and "has no" in res.reason and "class" in res.reason, res.reason


def test_an_open_vocabulary_map_keeps_the_stand_in_rule(emb) -> None:
    res = _lounge(emb, {}).query("the armchair")
    assert not res.found, res.reason


def test_a_table_at_dining_height_is_no_coffee_table(emb) -> None:
    cmap = captioned_map([make_obj(1, "table", (2.0, 2.0), (1.6, 0.9, 0.76), (150, 100, 60)),
                          make_obj(2, "chair", (3.5, 2.0), (0.45, 0.5, 0.9), (90, 90, 90))],
                         emb, grid_with_wall(-0.5, -0.5, 9.0, 7.0))
    cmap.meta.update(COCO)
    res = Retriever(cmap, emb).query("the coffee table")
    assert not res.found, res.reason
