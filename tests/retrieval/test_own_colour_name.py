"""The map's own colour name is never refused by its own verifier: an object whose observed colour
the captioner names "teal" (its nearest palette colour, however far) is a teal object for "the teal
chair". Before, the verifier's refusal (plausibility under ``color_reject``) and the captioner's
naming (nearest palette colour) disagreed on about one colour in twelve: dark teals, deep reds,
greyish olives. Colours drawn for this test (random sRGB values named by ``name_lab`` whose
agreement with their own name is under the refusal threshold), none from the development sets."""

from __future__ import annotations

import re

import pytest

from language.synth import grid_with_wall, make_obj, offline_retriever

# sRGB colours whose nearest palette name agrees with them under 0.30 (exp(-dE00/12)).
FAR_FROM_THEIR_NAME = [(76, 230, 172), (127, 10, 41), (114, 141, 104), (115, 105, 125), (206, 251, 97),
                       (165, 123, 213), (137, 67, 77), (225, 98, 108)]


@pytest.mark.parametrize("rgb", FAR_FROM_THEIR_NAME)
def test_the_colour_the_caption_says_is_not_refused(rgb: tuple[int, int, int]) -> None:
    objs = [make_obj(1, "chair", (1.0, 1.0), (0.5, 0.5, 0.9), rgb, shading=(0.95, 1.0)),
            make_obj(2, "bed", (6.0, 4.0), (1.6, 2.0, 0.5), (205, 200, 195))]
    r = offline_retriever(objs, grid_with_wall(-1, -1, 8, 6))
    caption = next(o.caption for o in r.cmap.objects if o.id == 1)
    m = re.search(r"an? ((?:dark |light )?[a-z]+) chair", caption or "")
    assert m is not None, caption
    res = r.query(f"the {m.group(1)} chair")
    assert res.found and res.chosen is not None and res.chosen.id == 1, (caption, res.reason)
