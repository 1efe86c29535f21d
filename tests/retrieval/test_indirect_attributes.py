"""Indirect attributes: an adjective the plain word lists lack but WordNet relates to an attribute
the map reads (a shape, a material, a colour) is read as that attribute; one that relates to
nothing the map observes stays neutral and never refuses.

Sentences and scenes written for this test (none from the development phrasings).
"""

from __future__ import annotations

import numpy as np
import pytest

from capnav.language import create_captioner, create_embedder
from capnav.language.describe import describe_map
from capnav.retrieval import Retriever
from capnav.retrieval.query import parse_instruction
from language.synth import disc_points, make_map, make_obj, textured_view


@pytest.fixture(scope="module")
def emb():
    return create_embedder("minilm")


def _board(center: tuple[float, float], w: float, d: float, h: float = 0.75) -> np.ndarray:
    rng = np.random.default_rng(11)
    return np.stack([center[0] - w / 2 + rng.uniform(0, w, 3000), center[1] - d / 2 + rng.uniform(0, d, 3000),
                     rng.uniform(0, h, 3000)], 1).astype(np.float32)


def scene(keep: set[int] | None = None) -> list:
    """A round and a rectangular side table, a wood-grained and a plain stool (same brown), a red
    and a blue armchair."""
    brown = (110, 75, 50)
    objs = [
        make_obj(1, "table", (1.0, 1.0), (0.9, 0.9, 0.75), (150, 110, 70)),
        make_obj(2, "table", (4.0, 1.0), (1.2, 0.8, 0.75), (150, 110, 70)),
        textured_view(make_obj(3, "stool", (1.0, 4.0), (0.4, 0.4, 0.7), brown, shading=(1.0, 1.0)), "wood", texel=2),
        textured_view(make_obj(4, "stool", (3.0, 4.0), (0.4, 0.4, 0.7), brown, shading=(1.0, 1.0)), "plastic",
                      texel=2),
        make_obj(5, "armchair", (6.0, 1.0), (0.8, 0.8, 0.9), (205, 30, 25)),
        make_obj(6, "armchair", (6.0, 4.0), (0.8, 0.8, 0.9), (35, 80, 215)),
    ]
    objs[0].points = disc_points((1.0, 1.0), 0.45, 0.75)
    objs[1].points = _board((4.0, 1.0), 1.2, 0.8)
    return [o for o in objs if keep is None or o.id in keep]


def retriever(emb, keep: set[int] | None = None) -> Retriever:
    cmap = make_map(scene(keep))
    describe_map(cmap, None, create_captioner("offline"), emb, progress=False)
    return Retriever(cmap, emb)


@pytest.mark.parametrize(("text", "shape"), [
    ("take me to the disc-shaped coffee table", "round"),  # WordNet's cluster of round.a.01
    ("the globular lamp in the hall", "round"),
    ("the rounded stool", "round"),  # rounded.a.01 is an also-see of round.a.01
    ("could you find the boxy cabinet", "rectangular"),  # its gloss: "resembling a box in rectangularity"
    ("the oblong coffee table please", "long"),  # similar to long.a.02
    ("the squarish ottoman", "square"),
    ("go to the arched floor lamp", "curved"),
])
def test_shape_adjectives_reach_the_shape_words(text, shape):
    q = parse_instruction(text)
    assert shape in q.shapes, q.to_dict()
    assert not q.unknown_words, q.to_dict()


@pytest.mark.parametrize(("text", "material"), [
    ("the see-through coffee table", "glass"),  # glass.n.01: "a brittle transparent solid"
    ("head over to the transparent table", "glass"),
    ("the timber dining table", "wood"),  # lumber.n.01: "the wood of trees cut and prepared ..."
    ("take me to the wooden-topped desk", "wooden"),  # a material word before a participle names the material (as said)
    ("the leather-covered stool", "leather"),
])
def test_material_adjectives_reach_the_material(text, material):
    q = parse_instruction(text)
    assert material in q.materials, q.to_dict()
    assert not q.unknown_words, q.to_dict()


@pytest.mark.parametrize(("text", "colour"), [
    ("the vermilion armchair", "scarlet"),  # scarlet.n.01 (vermilion), a shade word of the colour table
    ("the azure sofa", "blue"),  # azure.n.01 under blue.n.01
    ("find the cerulean chair", "blue"),
    ("the chartreuse stool", "yellowish green"),  # its adjective is derived from yellow_green.n.01
    ("go to the tangerine armchair", "reddish orange"),  # its definition: "of a strong reddish orange color"
])
def test_colour_words_beyond_the_colour_table_reach_their_nearest_colour(text, colour):
    q = parse_instruction(text)
    assert colour in q.colors, q.to_dict()
    assert not q.unknown_words, q.to_dict()


def test_indirect_words_choose_and_refuse_like_the_plain_ones(emb):
    r = retriever(emb)
    assert r.query("the disc-shaped table").chosen.id == 1
    assert r.query("take me to the oblong table").chosen.id == 2
    assert r.query("the timber stool").chosen.id == 3
    assert r.query("the see-through stool").chosen.id == 4  # glass shows a plain surface
    assert r.query("the vermilion armchair").chosen.id == 5
    assert r.query("go to the azure armchair").chosen.id == 6
    # On evidence against them they refuse, as the plain words do.
    only_round = retriever(emb, {1, 5})
    res = only_round.query("the oblong table")
    assert not res.found and "round" in res.reason
    only_grained = retriever(emb, {3, 5})
    res = only_grained.query("the transparent stool")
    assert not res.found and "grainy" in res.reason
    only_blue = retriever(emb, {2, 6})
    assert not only_blue.query("the vermilion armchair").found


@pytest.mark.parametrize("text", ["the squishy armchair", "the cushioned armchair", "the dead straight table",
                                  "the comfy-looking armchair"])
def test_an_adjective_that_maps_to_nothing_observed_stays_neutral(emb, text):
    q = parse_instruction(text)
    assert not q.shapes and not q.materials and not q.colors, q.to_dict()
    res = retriever(emb, {2, 5}).query(text)
    assert res.found, res.reason


def test_softness_words_are_known_but_unobserved():
    # soft.a.01's cluster ("squishy", "padded", "cushioned") says what no map observes: read, never judged.
    for text in ("the squishy armchair", "the padded chair", "a cushiony ottoman"):
        q = parse_instruction(text)
        assert not q.unknown_words, q.to_dict()
        assert any("soft" in n for n in q.notes), q.notes


@pytest.mark.parametrize("text", ["the stool that isn't wooden", "take me to the stool not made of wood",
                                  "the non-wooden stool", "the stool which is not made out of timber",
                                  "find me a stool that's not wood"])
def test_a_negated_material_excludes_the_stool_that_shows_it(emb, text):
    res = retriever(emb, {3, 4}).query(text)
    assert res.found and res.chosen.id == 4, res.reason


def test_a_negated_material_no_pixels_show_neither_excludes_nor_refuses(emb):
    # Metal shows nothing in pixels: "not metal" cannot tell the stools apart, and refuses neither.
    res = retriever(emb, {3, 4}).query("the stool that isn't made of metal")
    assert res.found, res.reason
    q = parse_instruction("the non-leather armchair")
    assert q.negations and "leather" in q.negations[0] and not q.unknown_words, q.to_dict()
