"""What a retriever keeps between asks answers as a fresh computation: a kept reading of an
instruction is the parse of it, each caller gets a copy of its own to change, and the second ask
of a sentence gives the first's answer; a kept colour agreement is the CIEDE2000 one."""

from __future__ import annotations

import numpy as np
import pytest

from capnav.api import CapNav
from capnav.language.colors import color_agreement, color_distance
from capnav.retrieval.query import parse_goals
from language.synth import described_living_map


@pytest.fixture(scope="module")
def nav(tmp_path_factory: pytest.TempPathFactory) -> CapNav:
    return CapNav.open(described_living_map(tmp_path_factory.mktemp("kept")))


@pytest.mark.parametrize("text", ["the grey sofa", "the lamp, then the bed", "somewhere to sit",
                                  "the closest chair to the stove"])
def test_a_kept_reading_is_the_parse_and_a_copy_of_its_own(nav: CapNav, text: str) -> None:
    r = nav.retriever
    fresh = [q.to_dict() for q in parse_goals(text, r.embedder)]
    first = r.read_goals(text)
    assert [q.to_dict() for q in first] == fresh
    first[0].notes.append("changed by a caller")
    first[0].colors.append("purple")
    assert [q.to_dict() for q in r.read_goals(text)] == fresh  # the kept reading did not change


def untimed(d: object) -> object:
    if isinstance(d, dict):
        return {k: untimed(v) for k, v in d.items() if k != "timings_ms"}
    return [untimed(v) for v in d] if isinstance(d, list) else d


def test_the_second_ask_of_a_sentence_answers_as_the_first(nav: CapNav) -> None:
    for text in ("the grey sofa", "the lamp, then the bed", "the bed"):
        a, b = nav.ask(text, robot=(2.0, 2.0)).to_dict(), nav.ask(text, robot=(2.0, 2.0)).to_dict()
        assert untimed(a) == untimed(b) and a["found"]


def test_a_kept_colour_agreement_is_the_ciede2000_one() -> None:
    rng = np.random.default_rng(0)
    for word in ("red", "light blue", "greenish", "navy"):
        for lab in rng.uniform([0, -60, -60], [100, 60, 60], (20, 3)):
            want = float(np.exp(-color_distance(word, lab) / 12.0))
            assert color_agreement(word, lab) == want and color_agreement(word, tuple(lab)) == want
    with pytest.raises(Exception, match="unknown colour word"):
        color_agreement("plaid", (50.0, 0.0, 0.0))
