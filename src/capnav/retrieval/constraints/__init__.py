"""An instruction as a list of constraints, each judged against what the map observed.

Ranking constraints (``RankingConstraint``: category, negation, room, relation, superlative,
distance, ordinal) narrow the candidates and key their order before verification; attribute
constraints (``AttributeConstraint``: name, colour, size, shape, material) are judged per
candidate by the verifier. Every module of this package registers its kind when imported, so
adding a kind is adding one module (and its tests).
"""

from __future__ import annotations

import importlib
import pkgutil
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from capnav.retrieval.constraints.base import (
    ATTRIBUTES,
    CONTRADICTED,
    RANKING,
    SORT_AT,
    SUPPORTED,
    UNOBSERVED,
    AttributeConstraint,
    Evidence,
    RankingConstraint,
    RankState,
    Status,
)
from capnav.retrieval.query import ParsedQuery
from capnav.retrieval.ranking import Ranking, keyed_order, semantic_order

if TYPE_CHECKING:
    from capnav.retrieval.constraints.view import Candidates

for _m in pkgutil.iter_modules(__path__):
    if _m.name != "base":
        importlib.import_module(f"{__name__}.{_m.name}")


def ranking_constraints(q: ParsedQuery) -> list[RankingConstraint]:
    """The ranking constraints ``q`` states, in the order they apply."""
    return [c() for c in RANKING if c.applies(q)]


def attribute_constraints(q: ParsedQuery) -> list[AttributeConstraint]:
    """The attribute constraints ``q`` states, in the order the verifier judges them."""
    return [c() for c in ATTRIBUTES if c.applies(q)]


def shown_kinds(evidence: list[Evidence]) -> list[str]:
    """The stated attributes the map shows outright on a candidate (``supported`` evidence of a
    kind whose support is an observation, ``AttributeConstraint.shown``: a material's grain)."""
    shown = {c.kind for c in ATTRIBUTES if c.shown}
    return [e.kind for e in evidence if e.kind in shown and e.status == SUPPORTED]


def shown_count(evidence: list[Evidence]) -> int:
    return len(shown_kinds(evidence))


def rank(r: Candidates, q: ParsedQuery, s: NDArray[np.float32], robot_xy: tuple[float, float] | None,
         notes: list[str]) -> tuple[Ranking, RankState]:
    """Apply the ranking constraints, sort, then the ones that read the order (an ordinal)."""
    st = RankState(r, q, s, robot_xy, notes)
    todo = ranking_constraints(q)
    for c in todo:
        if c.order < SORT_AT:
            c.rank(st)
    cfg = r.config
    if st.mode == "semantic":
        st.order, st.groups = semantic_order(r.E, s, st.pool, st.weights, cfg.top_k,
                                             cfg.mmr_lambda if cfg.use_mmr else None)
    else:
        st.order, st.groups = keyed_order(s, st.pool, st.group_keys, st.order_keys)
    at = {int(i): k for k, i in enumerate(st.pool)}
    terms = {int(i): {name: float(v[at[int(i)]]) for name, v in st.values.items()} for i in st.pool}
    for c in todo:
        if c.order >= SORT_AT:
            c.rank(st)
    return Ranking(st.order, st.groups, st.mode, st.predicate, st.weights, terms, st.refusal, st.refused_by,
                   dict(st.unmet), dict(st.out_of_reach), st.reach), st


__all__ = ["ATTRIBUTES", "CONTRADICTED", "RANKING", "SUPPORTED", "UNOBSERVED", "AttributeConstraint", "Evidence",
           "RankState", "RankingConstraint", "Status", "attribute_constraints", "rank", "ranking_constraints",
           "shown_count", "shown_kinds"]
