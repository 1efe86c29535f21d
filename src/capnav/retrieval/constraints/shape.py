"""Spoken shape words against the shape words the object's points gave (or a model caption's):
contradicted when an observed word excludes one (``form.shape_conflict``: "round" vs L-shaped)."""

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
class Shape(AttributeConstraint):
    kind = "shape"
    order = 40
    weight_field = "w_shape"
    shown = True

    @staticmethod
    def applies(q: ParsedQuery) -> bool:
        return bool(q.shapes)

    def judge(self, v: Judge, q: ParsedQuery, obj: MapObject, weight: float) -> Evidence:
        agree, why = v.shape(q, obj)
        if agree is None:
            return Evidence(self.kind, CONTRADICTED, 0.0, why)
        return Evidence(self.kind, SUPPORTED if agree > 0 else UNOBSERVED, agree, why, {"shape": round(agree, 3)})
