"""What a query returns: the chosen object, its scores, the runners-up and why, in words."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from capnav.mapping.objects import MapObject


@dataclass
class QueryResult:
    instruction: str
    chosen: MapObject | None
    found: bool
    score: float  # cosine similarity of the chosen object's caption (eq. 16), 0 when not found
    ranked: list[tuple[MapObject, float]]  # runners-up in decision order with their final score
    predicate: str | None  # "closest", "farthest", "largest", "smallest", "next to", "room", or None
    reason: str
    timings: dict[str, float] = field(default_factory=dict)  # seconds: embed, rank, verify
    mode: str = "semantic"
    distance_m: float | None = None  # robot to goal in the grid (eq. 17) when a robot position is known
    query: dict[str, Any] = field(default_factory=dict)
    #: Per runner-up: its terms (similarity, colour agreement, distance, ...), why it lost, its caption
    #: similarity and its verifier score (None when the verifier did not judge it).
    details: list[dict[str, Any]] = field(default_factory=list)
    terms: dict[str, float] = field(default_factory=dict)  # the chosen object's terms
    verification: float | None = None  # the verifier's score of the chosen object (None: not judged)
    #: Why the chosen object does not meet the request's relation ("next to" a landmark it stands
    #: 1.6 m from), None when it does or the request has none: the best there is, not what was asked.
    unmet: str | None = None
    #: When the query refused because every candidate stands beyond the request's relation of
    #: nearness (``found`` False, ``chosen`` None): the best of them, which ``unmet`` is about. A
    #: robot's search starts from it; ``capnav query --json`` gives it as ``unmet_candidate``.
    unmet_candidate: MapObject | None = None

    def runners_up(self) -> list[dict[str, Any]]:
        out = []
        for k, (o, s) in enumerate(self.ranked):
            d = self.details[k] if k < len(self.details) else {}
            out.append({"id": o.id, "label": o.label, "caption": o.caption,
                        "position": [round(float(v), 4) for v in o.position], "score": round(s, 6),
                        **({"terms": d["terms"], "why": d["why"]} if d else {})})
        return out

    def to_dict(self) -> dict[str, Any]:
        def obj(o: MapObject) -> dict[str, Any]:
            return {"id": o.id, "label": o.label, "caption": o.caption,
                    "position": [round(float(v), 4) for v in o.position]}

        return {
            "instruction": self.instruction, "found": self.found,
            "chosen": obj(self.chosen) if self.chosen is not None else None,
            "score": round(self.score, 6), "predicate": self.predicate, "mode": self.mode,
            "distance_m": None if self.distance_m is None else round(self.distance_m, 4),
            "reason": self.reason,
            "unmet": self.unmet,
            "unmet_candidate": obj(self.unmet_candidate) if self.unmet_candidate is not None else None,
            "terms": self.terms,
            "runners_up": self.runners_up(),
            "timings": {k: round(v, 6) for k, v in self.timings.items()},
            "query": self.query,
        }
