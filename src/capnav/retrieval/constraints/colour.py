"""A spoken colour against the object's measured colours (CIEDE2000 agreement, ``color_fit``):
contradicted when no shade the word covers is plausible for any observed colour."""

from __future__ import annotations

from typing import TYPE_CHECKING

from capnav.retrieval.constraints.base import CONTRADICTED, SUPPORTED, AttributeConstraint, Evidence, attribute
from capnav.retrieval.query import ParsedQuery

if TYPE_CHECKING:
    from capnav.mapping.objects import MapObject
    from capnav.retrieval.verifier import OfflineVerifier


@attribute
class Colour(AttributeConstraint):
    kind = "colour"
    order = 20
    weight_field = "w_color"

    @staticmethod
    def applies(q: ParsedQuery) -> bool:
        return bool(q.colors)

    def judge(self, v: OfflineVerifier, q: ParsedQuery, obj: MapObject, weight: float) -> Evidence:
        col, fit, why = v.color_fit(q, obj)
        terms = {"colour": round(col, 3)}
        reject = v.config.color_reject
        if fit < reject:
            return Evidence(self.kind, CONTRADICTED, 0.0, f"{why}, below {reject:.2f}", terms)
        return Evidence(self.kind, SUPPORTED, col, why, terms)
