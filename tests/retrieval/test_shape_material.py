"""Material and shape words against what the map observed: agreement ranks higher, a clear
contradiction is refused with the reason, weak evidence decides nothing.

One living room of synthetic objects whose views are crops of the simulator's procedural
textures and whose points are drawn for their shape; sentences are written for this scene, none
is taken from the development phrasings.
"""

from __future__ import annotations

import pytest

from capnav.language import create_captioner, create_embedder
from capnav.language.describe import describe_map
from capnav.retrieval import Retriever
from language.synth import disc_points, make_map, make_obj, plant_points, textured_view


@pytest.fixture(scope="module")
def emb():
    return create_embedder("minilm")


def _board(center: tuple[float, float], w: float, d: float):
    import numpy as np

    rng = np.random.default_rng(7)
    return np.stack([center[0] - w / 2 + rng.uniform(0, w, 3000), center[1] - d / 2 + rng.uniform(0, d, 3000),
                     rng.uniform(0, 0.75, 3000)], 1).astype(np.float32)


def room(keep: set[int] | None = None) -> list:
    pink = (235, 140, 180)
    objs = [
        textured_view(make_obj(1, "armchair", (1.0, 1.0), (0.8, 0.8, 0.9), pink, shading=(1.0, 1.0)), "fabric"),
        textured_view(make_obj(2, "armchair", (4.0, 1.0), (0.8, 0.8, 0.9), pink, shading=(1.0, 1.0)), "leather"),
        make_obj(3, "table", (1.5, 4.0), (0.9, 0.9, 0.75), (150, 110, 70)),
        make_obj(4, "table", (4.5, 4.0), (1.2, 0.8, 0.75), (150, 110, 70)),
        make_obj(5, "plant", (7.0, 1.0), (0.7, 0.7, 1.1), (50, 125, 45)),
        make_obj(6, "plant", (7.0, 4.5), (0.3, 0.3, 1.1), (50, 125, 45)),
    ]
    objs[2].points = disc_points((1.5, 4.0), 0.45, 0.75)
    objs[3].points = _board((4.5, 4.0), 1.2, 0.8)
    objs[4].points = plant_points((7.0, 1.0), 0.35)
    objs[5].points = plant_points((7.0, 4.5), 0.06)
    return [o for o in objs if keep is None or o.id in keep]


def retriever(emb, keep: set[int] | None = None, scene=None) -> Retriever:
    """The offline-captioned map of ``scene`` (default: ``room``), only objects ``keep`` if given."""
    cmap = make_map((scene or room)(keep))
    describe_map(cmap, None, create_captioner("offline"), emb, progress=False)
    return Retriever(cmap, emb)


def test_the_observed_words_reach_the_attribute_cache(emb):
    cmap = make_map(room())
    describe_map(cmap, None, create_captioner("offline"), emb, progress=False)
    attrs = cmap.caches["attributes"]
    assert attrs["1"]["surface"][0] == "woven" and attrs["2"]["surface"][0] == "smooth"
    assert attrs["3"]["shapes"] == ["round"] and attrs["4"]["shapes"] == ["rectangular"]
    assert "leafy" in attrs["5"]["shapes"] and "slender" in attrs["6"]["shapes"]


def test_material_agreement_chooses_between_lookalikes(emb):
    r = retriever(emb)
    assert r.query("could you take me to the leather armchair").chosen.id == 2
    res = r.query("the pink fabric armchair please")
    assert res.chosen.id == 1 and res.terms.get("material") == 1.0


def test_a_material_the_pixels_contradict_is_refused_with_the_reason(emb):
    only_woven = retriever(emb, {1, 3, 4, 5, 6})
    res = only_woven.query("go to the leather armchair")
    assert not res.found and "woven" in res.reason
    only_smooth = retriever(emb, {2, 3, 4, 5, 6})
    assert not only_smooth.query("find the cotton armchair").found
    # Velvet's pile shows no weave: a smooth armchair may be velvet.
    assert only_smooth.query("find the velvet armchair").chosen.id == 2


def test_round_and_rectangular_tables(emb):
    r = retriever(emb)
    assert r.query("head to the round table").chosen.id == 3
    assert r.query("the rectangular table").chosen.id == 4
    res = retriever(emb, {1, 2, 4, 5, 6}).query("head to the round table")
    assert not res.found and "rectangular" in res.reason


def test_plant_growth_words(emb):
    r = retriever(emb)
    assert r.query("the bushy plant").chosen.id == 5
    assert r.query("take me to the slender plant").chosen.id == 6
    res = retriever(emb, {1, 2, 3, 4, 5}).query("take me to the slender plant")
    assert not res.found and "leafy" in res.reason


def test_cactus_words_reach_the_columnar_growth_form(emb):
    # WordNet: a cactus is a succulent "usually having spines"; the lexicon ties these words to the
    # "slender" growth the points show (foliage narrower than the pot).
    r = retriever(emb)
    for text in ("go to the cactus", "the spiny plant please", "take me to the succulent", "the thorny houseplant"):
        res = r.query(text)
        assert res.chosen is not None and res.chosen.id == 6, (text, res.reason)
    res = retriever(emb, {1, 2, 3, 4, 5}).query("go to the cactus")
    assert not res.found and "leafy" in res.reason  # the only plant spreads wider than its pot


def test_a_size_word_ranks_among_the_cacti(emb):
    small = make_obj(7, "plant", (2.5, 2.5), (0.2, 0.2, 0.7), (50, 125, 45))
    small.points = plant_points((2.5, 2.5), 0.05, seed=3)
    small.points[:, 2] *= 0.7 / 1.1
    cmap = make_map([*room({5, 6}), small])
    describe_map(cmap, None, create_captioner("offline"), emb, progress=False)
    r = Retriever(cmap, emb)
    # The leafy plant is the biggest plant, but no cactus: "the larger cactus" is the larger of the two.
    assert r.query("the larger cactus").chosen.id == 6
    assert r.query("the smaller cactus").chosen.id == 7
    assert r.query("the bigger plant").chosen.id == 5


def grain_room(keep: set[int] | None = None) -> list:
    """Lookalikes told apart by their grain only: two brown stools (wood, plastic), two beige
    armchairs (velvet, leather), one olive velvet sofa, texels drawn as the renderer draws a near
    face; and a navy chair without views."""
    brown, beige = (110, 75, 50), (205, 185, 150)
    objs = [
        textured_view(make_obj(1, "stool", (1.0, 1.0), (0.4, 0.4, 0.7), brown, shading=(1.0, 1.0)), "wood", texel=2),
        textured_view(make_obj(2, "stool", (3.0, 1.0), (0.4, 0.4, 0.7), brown, shading=(1.0, 1.0)), "plastic",
                      texel=2),
        textured_view(make_obj(3, "armchair", (1.0, 4.0), (0.8, 0.8, 0.9), beige, shading=(1.0, 1.0)), "velvet",
                      texel=2),
        textured_view(make_obj(4, "armchair", (3.5, 4.0), (0.8, 0.8, 0.9), beige, shading=(1.0, 1.0)), "leather",
                      texel=2),
        textured_view(make_obj(5, "sofa", (6.5, 3.0), (2.0, 0.9, 0.8), (120, 120, 60), shading=(1.0, 1.0)), "velvet",
                      texel=2),
        make_obj(6, "chair", (6.5, 5.5), (0.5, 0.5, 0.9), (40, 40, 110)),  # never seen up close: no surface
    ]
    return [o for o in objs if keep is None or o.id in keep]


def test_the_grain_picks_the_wooden_stool_and_the_plain_one_among_lookalikes(emb):
    r = retriever(emb, scene=grain_room)
    res = r.query("I'd like to go to the wooden stool")
    assert res.chosen.id == 1 and res.terms.get("material") == 1.0
    assert r.query("take me to the plastic stool").chosen.id == 2
    assert r.query("bring me to the leather armchair please").chosen.id == 4
    assert r.query("the beige velvet armchair").chosen.id == 3


def test_a_grain_the_pixels_contradict_is_refused_naming_the_surface(emb):
    plain = retriever(emb, {2, 3, 5}, grain_room)  # plastic stool, velvet armchair, velvet sofa
    res = plain.query("go to the leather sofa")
    assert not res.found and "plain" in res.reason and "leather" in res.reason
    assert plain.query("go to the velvet sofa").chosen.id == 5
    res = plain.query("the wooden stool")
    assert not res.found and "plain" in res.reason
    # A chair may stand in for a sofa, but not for "the leather sofa" when its surface was not seen.
    assert not retriever(emb, {5, 6}, grain_room).query("go to the leather sofa").found
    assert retriever(emb, {5, 6}, grain_room).query("go to the sofa").chosen.id == 5


def dark_room(keep: set[int] | None = None) -> list:
    """Near-black things seen from afar (textures minified, not drawn texel by texel): a black
    wooden stool, a black metal lamp, a black fabric armchair; and a bright grey plastic stool."""
    black = (22, 20, 21)
    objs = [
        textured_view(make_obj(1, "stool", (1.0, 1.0), (0.35, 0.35, 0.5), black, shading=(1.0, 1.0)), "wood"),
        textured_view(make_obj(2, "lamp", (3.0, 1.0), (0.3, 0.3, 1.1), black, shading=(1.0, 1.0)), "metal"),
        textured_view(make_obj(3, "armchair", (5.0, 1.0), (0.8, 0.8, 0.9), black, shading=(1.0, 1.0)), "fabric"),
        textured_view(make_obj(4, "stool", (1.0, 4.0), (0.35, 0.35, 0.5), (190, 190, 195), shading=(1.0, 1.0)),
                      "plastic", texel=2),
    ]
    return [o for o in objs if keep is None or o.id in keep]


def test_near_black_surfaces_neither_confirm_nor_refuse_a_material(emb):
    # A black stool and a black lamp shade: their pixels' texture is below what 8 bits resolve
    # there, so "wooden" and "metal" are unobserved, not refused as a weave.
    only_black = retriever(emb, {1, 2, 3}, dark_room)
    res = only_black.query("the wooden stool")
    assert res.found and res.chosen.id == 1, res.reason
    res = only_black.query("the black metal lamp")
    assert res.found and res.chosen.id == 2, res.reason
    # The bright plastic stool's plain surface still refuses "wooden".
    res = retriever(emb, {1, 4}, dark_room).query("the wooden stool")
    assert res.chosen.id == 1 and any("plain" in r["why"] for r in res.runners_up())
    assert not retriever(emb, {4}, dark_room).query("the wooden stool").found


@pytest.mark.parametrize(("text", "oid"), [
    ("the chenille armchair", 1),  # a fabric by name
    ("take me to the tweedy-looking... no, the tweed armchair", 1),
    ("the armchair in suede", 2),  # a leather
    ("my leathery pink armchair", 2),
])
def test_material_words_beyond_the_plain_names_reach_their_material(emb, text, oid):
    """WordNet's material words (a kind of fabric or leather, an adjective derived from one) are
    read as the material the surface test knows, so they choose between the lookalikes."""
    res = retriever(emb).query(text)
    assert res.found and res.chosen.id == oid, res.reason
    assert "material" in res.terms, res.terms  # judged as a material (leather's mottle: 0.5 here)


def test_a_kind_of_material_the_pixels_contradict_is_refused(emb):
    only_woven = retriever(emb, {1, 3, 4, 5, 6})
    res = only_woven.query("the suede armchair")
    assert not res.found and "woven" in res.reason


def test_material_words_are_read_as_their_material_and_nothing_else():
    from capnav.retrieval.query import parse_instruction

    assert parse_instruction("the sofa with the velvety feel").materials == ["velvet"]
    assert parse_instruction("a teak side table").materials == ["wood"]
    assert parse_instruction("the brass floor lamp").materials == ["metal"]
    # verbs first ("lead me"), colour words ("walnut") and category words keep their role
    assert parse_instruction("lead me to the sofa").materials == []
    walnut = parse_instruction("the walnut table")
    assert walnut.materials == [] and walnut.colors
