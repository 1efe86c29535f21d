"""The candidate's name against the named target (verification): the named category (weight 1),
an alternative the parser offered (its weight below 1, a stand-in), or, for a word outside the
vocabulary, a caption name close to it by embedding. Judged first: the others read its weight."""

from __future__ import annotations

from typing import TYPE_CHECKING

from capnav.retrieval.constraints.base import CONTRADICTED, SUPPORTED, Evidence
from capnav.retrieval.query import ParsedQuery

if TYPE_CHECKING:
    from capnav.mapping.objects import MapObject
    from capnav.retrieval.constraints.view import Judge


class Name:
    kind = "name"

    def judge(self, v: Judge, q: ParsedQuery, obj: MapObject) -> Evidence:
        """``value`` is the category weight: 1 for the named category, < 1 for a stand-in."""
        ok, weight, why = v.name_agreement(q, obj)
        if not ok:
            return Evidence(self.kind, CONTRADICTED, 0.0, why)
        return Evidence(self.kind, SUPPORTED, weight, why, {"category": round(weight, 3)} if weight < 1.0 else {})
