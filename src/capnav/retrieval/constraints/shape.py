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
    #: Not ``shown``: an outline word is said only above the footprint's resolution, so a small
    #: object's outline is unobserved far more often than a large one's, and putting the objects
    #: that show a shape first would override the size said with it (a small plant's growth word
    #: goes unseen where the big ones' is seen: a development-set request dropped when it was).

    @staticmethod
    def applies(q: ParsedQuery) -> bool:
        return bool(q.shapes)

    def judge(self, v: Judge, q: ParsedQuery, obj: MapObject, weight: float) -> Evidence:
        agree, why = v.shape(q, obj)
        if agree is None:
            return Evidence(self.kind, CONTRADICTED, 0.0, why)
        return Evidence(self.kind, SUPPORTED if agree > 0 else UNOBSERVED, agree, why, {"shape": round(agree, 3)})
