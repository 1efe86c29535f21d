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
    ranked: list[tuple[MapObject, float]]  # runners-up in retrieval order with their cosine
    predicate: str | None  # "closest", "farthest", "largest", "smallest", "next to", "room", or None
    reason: str
    timings: dict[str, float] = field(default_factory=dict)  # seconds: embed, rank, verify
    mode: str = "semantic"
    distance_m: float | None = None  # robot to goal in the grid (eq. 17) when a robot position is known
    query: dict[str, Any] = field(default_factory=dict)

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
            "runners_up": [{**obj(o), "score": round(s, 6)} for o, s in self.ranked],
            "timings": {k: round(v, 6) for k, v in self.timings.items()},
            "query": self.query,
        }
