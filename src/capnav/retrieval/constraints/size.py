"""A size word ("the big lamp") against the object's mapped volume among its own category: 1 at
the named end, 0 at the other, unobserved (0.5) when the category's volumes are too close to tell.
It orders, never refuses: size is relative to what else the map holds."""

from __future__ import annotations

from typing import TYPE_CHECKING

from capnav.retrieval.constraints.base import SUPPORTED, UNOBSERVED, AttributeConstraint, Evidence, attribute
from capnav.retrieval.query import ParsedQuery

if TYPE_CHECKING:
    from capnav.mapping.objects import MapObject
    from capnav.retrieval.constraints.view import Judge


@attribute
class Size(AttributeConstraint):
    kind = "size"
    order = 30
    weight_field = "w_size"

    @staticmethod
    def applies(q: ParsedQuery) -> bool:
        return q.size_word is not None

    def judge(self, v: Judge, q: ParsedQuery, obj: MapObject, weight: float) -> Evidence:
        size = v.size(q, obj)
        return Evidence(self.kind, UNOBSERVED if size == 0.5 else SUPPORTED, size, "", {"size": round(size, 3)})
