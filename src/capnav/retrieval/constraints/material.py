"""Spoken materials against the surface the object's pixels showed (a weave, grain, a plain
surface): supported (1) when the pixels show what the material shows, unobserved (0.5) when
nothing clear was seen or the word says nothing pixels can show, contradicted on a surface that
excludes it. A stand-in category (weight < 1) must show the material to serve."""

from __future__ import annotations

from typing import TYPE_CHECKING

from capnav.language.surface import material_shows
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
class Material(AttributeConstraint):
    kind = "material"
    order = 50
    weight_field = "w_material"
    shown = True

    @staticmethod
    def applies(q: ParsedQuery) -> bool:
        return bool(q.materials)

    def judge(self, v: Judge, q: ParsedQuery, obj: MapObject, weight: float) -> Evidence:
        mat, why = v.material(q, obj)
        if mat is None:
            return Evidence(self.kind, CONTRADICTED, 0.0, why)
        if weight < 1.0 and mat < 1.0 and any(map(material_shows, q.materials)):
            # Another category stands in for the named one only when its pixels show the spoken
            # material: "the leather stool" is not a chair of unknown surface.
            return Evidence(self.kind, CONTRADICTED, 0.0,
                            f"its pixels do not show {'/'.join(q.materials)} ({why})")
        return Evidence(self.kind, SUPPORTED if mat >= 1.0 else UNOBSERVED, mat, why, {"material": round(mat, 3)})
