"""Colours as people say them: shades and modifiers land on CIELAB points with distances."""

from __future__ import annotations

import numpy as np
import pytest

from capnav.core.errors import InputError
from capnav.language.colors import LEX_LAB, NAMES, color_agreement, color_distance, color_lab, family


def lab(name: str) -> np.ndarray:
    return LEX_LAB[NAMES.index(name)]


@pytest.mark.parametrize(("phrase", "nearest"), [
    ("reddish", "red"), ("whitish", "white"), ("off-white", "cream"), ("navy", "navy"), ("light grey", "light grey"),
    ("light gray", "light grey"), ("dark wooden", "walnut"), ("beige", "beige"), ("charcoal", "dark grey"),
    ("mustard-coloured", "mustard"), ("pinkish", "pink"), ("bluish", "blue"), ("greyish", "grey"),
    ("crimson", "red"), ("lilac", "pink"), ("pale yellow", "yellow"),
])
def test_shades_land_near_their_palette_colour(phrase, nearest):
    d = {n: color_distance(phrase, lab(n)) for n in NAMES}
    assert min(d, key=d.__getitem__) == nearest, sorted(d.items(), key=lambda kv: kv[1])[:3]


def test_disagreement_is_measurable():
    # "purple" against a pink object: a clear distance, larger than between a colour and its shade.
    assert color_distance("purple", lab("pink")) > 15
    assert color_distance("pinkish", lab("pink")) < 10
    assert color_distance("reddish", lab("red")) < color_distance("reddish", lab("orange"))
    assert color_agreement("whitish", lab("white")) > 0.9 > color_agreement("whitish", lab("grey"))
    assert color_distance("light grey", lab("white")) < color_distance("dark grey", lab("white"))
    # Modifiers move a colour: "dark blue" towards navy, "pale yellow" towards cream.
    assert color_distance("dark blue", lab("navy")) < color_distance("blue", lab("navy"))
    assert color_distance("pale yellow", lab("cream")) < color_distance("yellow", lab("cream"))


@pytest.mark.parametrize("phrase", ["wooden", "light", "sofa", "yellow terracotta", "", "banana"])
def test_non_colours(phrase):
    assert color_lab(phrase) is None
    with pytest.raises(InputError):
        color_distance(phrase, (50.0, 0.0, 0.0))


def test_a_basic_colour_word_covers_its_shades_only():
    # Mustard is a yellow and walnut a brown; shades between two terms (indigo: purple or blue?)
    # belong to neither, and pink is no purple.
    assert "mustard" in family("yellow") and "walnut" in family("brown")
    assert {"forest green", "olive green"} <= set(family("green"))
    assert family("purple") == ("purple",)
    assert "pink" not in family("purple") and "purple" not in family("pink")
    assert family("gray") == family("grey") and family("grey")[0] == "grey"
    # A word that is not a basic term covers itself only.
    assert family("mustard") == ("mustard",) and family("pale pink") == ("pale pink",)
