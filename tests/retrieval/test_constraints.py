"""The constraint list: every kind registered by its own module, evidence per candidate in three
states, and the reason, the refusal and the runners-up built from the same evidence.

A one-room scene of synthetic objects written for these tests (no sentence of the development
phrasings)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from capnav.language import create_embedder
from capnav.retrieval import Retriever, parse_instruction
from capnav.retrieval.constraints import (
    ATTRIBUTES,
    CONTRADICTED,
    RANKING,
    SUPPORTED,
    UNOBSERVED,
    RankingConstraint,
    RankState,
    attribute_constraints,
    ranking_constraints,
)
from capnav.retrieval.constraints.base import ranking
from language.synth import captioned_map, grid_with_wall, make_obj


@pytest.fixture(scope="module")
def emb():
    return create_embedder("minilm")


@pytest.fixture(scope="module")
def retriever(emb):
    objs = [
        make_obj(1, "armchair", (1.0, 1.0), (0.8, 0.8, 0.9), (30, 60, 160)),  # blue
        make_obj(2, "armchair", (4.0, 1.0), (0.8, 0.8, 0.9), (200, 40, 40)),  # red
        make_obj(3, "armchair", (7.0, 1.0), (1.0, 1.0, 1.0), (30, 140, 60)),  # green, larger
        make_obj(4, "lamp", (4.6, 1.6), (0.4, 0.4, 1.5), (240, 230, 220)),
        make_obj(5, "bed", (6.0, 5.0), (1.6, 2.0, 0.5), (230, 230, 230)),
    ]
    return Retriever(captioned_map(objs, emb, grid_with_wall(-0.5, -0.5, 9.0, 7.0)), emb)


def test_every_kind_is_registered_by_its_module():
    kinds = {c.kind for c in RANKING} | {c.kind for c in ATTRIBUTES}
    assert {"category", "detectable", "negation", "room", "relation", "superlative", "distance", "ordinal",
            "purpose", "colour", "size", "shape", "material"} <= kinds
    orders = [c.order for c in RANKING]
    assert orders == sorted(orders)


def test_a_query_states_only_its_own_constraints():
    q = parse_instruction("the big red armchair next to the lamp")
    assert {c.kind for c in ranking_constraints(q)} >= {"category", "relation"}
    assert "superlative" not in {c.kind for c in ranking_constraints(q)}
    assert {c.kind for c in attribute_constraints(q)} == {"colour", "size"}


def test_colour_evidence_is_supported_or_contradicted_per_candidate(retriever):
    q = parse_instruction("the red armchair")
    colour = next(c for c in attribute_constraints(q) if c.kind == "colour")
    ev = {o.id: colour.judge(retriever.judge, q, o, 1.0) for o in retriever.objects if o.label == "armchair"}
    assert ev[2].status == SUPPORTED and ev[1].status == ev[3].status == CONTRADICTED
    assert "colour red" in ev[1].clause


def test_a_rejected_runner_up_says_the_clause_of_the_constraint_that_refused_it(retriever):
    res = retriever.query("the red armchair")
    assert res.found and res.chosen.id == 2
    by_id = {o.id: d for (o, _), d in zip(res.ranked, res.details, strict=True)}
    for k in (1, 3):
        assert by_id[k]["why"].startswith("rejected: it is an armchair but colour red vs observed")
    # The chosen object's reason carries the clause of the same constraint, supported.
    assert "colour red vs observed" in res.reason


def test_the_refusal_is_the_clause_of_the_constraint_that_emptied_the_candidates(retriever):
    res = retriever.query("the purple armchair")
    assert not res.found
    assert "colour purple vs observed" in res.reason
    assert all(d["why"].startswith("rejected") for d in res.details)


def test_size_without_a_difference_is_unobserved_and_does_not_refuse(retriever):
    q = parse_instruction("the small lamp")  # the only lamp: its category's volumes cannot tell
    size = next(c for c in attribute_constraints(q) if c.kind == "size")
    lamp = next(o for o in retriever.objects if o.label == "lamp")
    assert size.judge(retriever.judge, q, lamp, 1.0).status == UNOBSERVED
    assert retriever.query("the small lamp").found


def test_a_new_kind_is_one_registered_class(retriever):
    """A kind defined here (prefer the candidate farthest from the origin) takes part in the
    ranking without any change elsewhere, and leaves the registry as it was when removed."""

    @ranking
    class FarFromOrigin(RankingConstraint):
        kind = "test-far-from-origin"
        order = 55

        @staticmethod
        def applies(q):
            return "yonder" in q.text

        def rank(self, st: RankState) -> None:
            d = np.linalg.norm(st.r.scene.xy[st.pool], axis=1)
            st.group_keys.append(-d)
            st.values["distance from origin (m)"] = d
            st.predicate, st.mode = "yonder", "predicate"

    try:
        q = dataclasses.replace(parse_instruction("the armchair yonder"))
        res = retriever.query(q)
        assert res.found and res.chosen.id == 3 and res.predicate == "yonder"
        assert any("distance from origin (m)" in d["terms"] for d in res.details)
    finally:
        RANKING.remove(FarFromOrigin)
    assert retriever.query("the armchair yonder").predicate != "yonder"


def test_a_purpose_says_the_order_of_fit_in_the_reason(retriever, emb):
    q = parse_instruction("where could I have a nap", emb)
    res = retriever.query(q)
    assert res.found and res.chosen.label == "bed"
    assert f"'{q.purpose}' is served best by bed" in res.reason
