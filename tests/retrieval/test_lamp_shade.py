"""A lamp is called by its shade: "the white lamp" is the one with the white shade, though every
lamp's pole and foot are the same grey metal. Counting the stand as the lamp's colour made every
lamp a little grey and so a little "white", and the caption-similarity order then chose a
terracotta lamp over the white one. Synthetic lamps: a metal pole and foot, a coloured shade on top."""

from __future__ import annotations

import numpy as np
import pytest

from capnav.language import create_embedder
from capnav.language.offline_captioner import ObservationCaptioner
from capnav.mapping.objects import MapObject
from capnav.retrieval import Retriever
from language.synth import captioned_map, grid_with_wall

GREY_METAL = (170, 172, 176)


def lamp(oid: int, xy: tuple[float, float], shade: tuple[int, int, int], seed: int = 0) -> MapObject:
    """A 1.6 m floor lamp as a map fuses it: foot and pole in grey metal (40% of the points), a
    0.36 m shade of ``shade`` colour on top, shaded by the light."""
    rng = np.random.default_rng(seed + oid)
    n_stand, n_shade = 240, 360
    foot = np.c_[rng.uniform(-0.14, 0.14, (80, 2)), rng.uniform(0.0, 0.03, 80)]
    pole = np.c_[rng.uniform(-0.015, 0.015, (n_stand - 80, 2)), rng.uniform(0.03, 1.3, n_stand - 80)]
    a = rng.uniform(0, 2 * np.pi, n_shade)
    top = np.c_[0.2 * np.cos(a), 0.2 * np.sin(a), rng.uniform(1.24, 1.6, n_shade)]
    pts = np.vstack([foot, pole, top]) + np.array([xy[0], xy[1], 0.0])
    base = np.array([GREY_METAL] * n_stand + [shade] * n_shade, dtype=np.float64)
    lin = (base / 255.0) ** 2.2 * rng.uniform(0.6, 1.0, (len(base), 1))
    cols = np.clip(255 * lin ** (1 / 2.2), 0, 255).astype(np.uint8)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    fp = np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])
    return MapObject(id=oid, label="lamp", label_votes={"lamp": 5.0}, position=(lo + hi) / 2, extent_min=lo,
                     extent_max=hi, footprint=fp, points=pts.astype(np.float32), colors=cols,
                     feature=np.zeros(4, np.float32), hits=5)


@pytest.fixture(scope="module")
def emb():  # type: ignore[no-untyped-def]
    return create_embedder("minilm")


def test_a_lamps_colour_is_its_shades() -> None:
    cap = ObservationCaptioner()
    white, rust = lamp(1, (1.0, 1.0), (236, 236, 232)), lamp(2, (4.0, 1.0), (190, 95, 60))
    assert [c.name for c in cap.colors(white)] == ["white"]
    names = [c.name for c in cap.colors(rust)]
    assert "grey" not in names and not any("grey" in n for n in names), names
    # another category keeps every point: a grey-legged table is grey and its top's colour
    table = lamp(3, (1.0, 4.0), (190, 95, 60))
    table.label, table.label_votes = "table", {"table": 5.0}
    assert any("grey" in c.name for c in cap.colors(table))


def test_the_white_lamp_among_lamps_on_grey_stands(emb) -> None:  # type: ignore[no-untyped-def]
    lamps = [lamp(1, (1.0, 1.0), (200, 100, 60)), lamp(2, (4.0, 1.0), (20, 20, 22)),
             lamp(3, (7.0, 1.0), (60, 140, 70)), lamp(4, (1.0, 5.0), (236, 236, 232))]
    cmap = captioned_map(lamps, emb, grid_with_wall(-1, -1, 9, 7))
    r = Retriever(cmap, emb)
    for text in ("the white lamp", "Would you navigate to the white floor lamp?", "the lamp that is white"):
        res = r.query(text)
        assert res.found and res.chosen is not None and res.chosen.id == 4, (text, res.reason)
    res = r.query("the black lamp")
    assert res.chosen is not None and res.chosen.id == 2, res.reason
