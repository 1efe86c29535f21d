"""An object's size overrules its leading label when a runner-up it also got fits (issue 21):
the dining table whose sightings mostly said "chair" (the chairs around it, whose boxes hold
pieces of its top) is a table. A label is only ruled out by a clear margin, only for labels
with a footprint prior, and only in favour of a runner-up with a fair share of the votes whose
own prior fits. Points written for this test."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.typing import NDArray

from capnav.mapping.label_fit import LabelFitConfig, fitting_label


def slab(long: float, short: float, z: float, n: int = 800, seed: int = 0) -> NDArray[np.float64]:
    """Points over a ``long`` x ``short`` m rectangle at height ``z``, turned 30 degrees."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform([-long / 2, -short / 2], [long / 2, short / 2], size=(n, 2))
    c, s = np.cos(np.pi / 6), np.sin(np.pi / 6)
    xy = xy @ np.array([[c, s], [-s, c]]) + [3.0, 2.0]
    return np.column_stack([xy, np.full(n, z)])


def test_a_table_top_voted_chair_is_the_table() -> None:
    label, why = fitting_label({"chair": 0.68, "table": 0.13}, slab(1.9, 1.6, 0.75))
    assert label == "table", why
    assert "chair" in why and "table" in why


def test_a_runner_up_without_a_prior_is_no_evidence_from_size() -> None:
    # a new chair fused with the stool beside it (1.7 m long): no "stool", and no "sofa" either
    assert fitting_label({"chair": 0.78, "stool": 0.43}, slab(1.7, 0.5, 0.45))[0] is None
    assert fitting_label({"chair": 3.0, "sofa": 0.7}, slab(2.0, 0.9, 0.45))[0] is None


@pytest.mark.parametrize(("votes", "points"), [
    ({"chair": 0.7, "table": 0.2}, slab(0.5, 0.5, 0.45)),    # a chair's size: it stays a chair
    ({"chair": 0.8, "sofa": 0.05}, slab(2.0, 0.9, 0.45)),    # too few sofa votes to say so
    ({"chair": 0.8}, slab(2.0, 0.9, 0.45)),                  # no runner-up
    ({"sofa": 0.8, "chair": 0.3}, slab(2.0, 0.9, 0.45)),     # a sofa has no prior to rule it out
    ({"chair": 0.7, "table": 0.2}, slab(1.2, 0.6, 0.45)),    # within the margin of a large chair
])
def test_the_leading_label_stays(votes: dict[str, float], points: NDArray[np.float64]) -> None:
    assert fitting_label(votes, points)[0] is None


def test_a_runner_up_ruled_out_too_does_not_take_over() -> None:
    # a 7 m long object: no chair and no table either (the table prior ends at 3.5 m, x 1.5)
    assert fitting_label({"chair": 0.7, "table": 0.3}, slab(7.0, 1.0, 0.75))[0] is None


def test_switched_off() -> None:
    assert fitting_label({"chair": 0.68, "table": 0.13}, slab(1.9, 1.6, 0.75), LabelFitConfig(enabled=False))[0] is None


def test_the_caption_names_the_label_the_size_allows() -> None:
    from capnav.language.context import SceneContext
    from capnav.language.offline_captioner import ObservationCaptioner
    from language.synth import make_obj

    o = make_obj(1, "table", (3.0, 2.0), (1.9, 1.6, 0.75), (150, 110, 70))
    o.points = slab(1.9, 1.6, 0.75).astype(np.float32)
    o.colors = np.full((len(o.points), 3), 140, dtype=np.uint8)
    o.label_votes = {"chair": 0.68, "table": 0.13}
    assert ObservationCaptioner().caption(o, SceneContext([o])).text.startswith("TABLE"), o.label_votes
