"""A spoken colour against the object's measured colours (CIEDE2000 agreement, ``color_fit``):
contradicted when no shade the word covers is plausible for any observed colour (``color_reject``,
measured by ``benchmarks/measure_evidence.py``); unobserved, neither for nor against, when no
colour of the object was measured."""

from __future__ import annotations

from typing import TYPE_CHECKING

from capnav.retrieval.constraints.base import (
    CONTRADICTED,
    SUPPORTED,
    UNOBSERVED,
    AttributeConstraint,
    Evidence,
    attribute,
)
from capnav.retrieval.query import ParsedQuery

if TYPE_CHECKING:
    from capnav.mapping.objects import MapObject
    from capnav.retrieval.constraints.view import Judge


@attribute
class Colour(AttributeConstraint):
    kind = "colour"
    order = 20
    weight_field = "w_color"

    @staticmethod
    def applies(q: ParsedQuery) -> bool:
        return bool(q.colors)

    def judge(self, v: Judge, q: ParsedQuery, obj: MapObject, weight: float) -> Evidence:
        col, fit, why = v.color_fit(q, obj)
        terms = {"colour": round(col, 3)}
        if not v.observed_colors(q, obj):
            # Nothing of its colour was measured (seen only in the dark, too few pixels): no
            # evidence either way, so it neither gains nor is refused.
            return Evidence(self.kind, UNOBSERVED, 0.0,
                            f"its colour was not observed (neither for nor against {'/'.join(q.colors)})", terms)
        reject = v.config.color_reject
        if fit < reject:
            return Evidence(self.kind, CONTRADICTED, 0.0, f"{why}, below {reject:.2f}", terms)
        return Evidence(self.kind, SUPPORTED, col, why, terms)
