"""Retrieval parameters (paper 3.4) with switches for the paper's two ablations."""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

from capnav.core.errors import InputError


@dataclass
class RetrievalConfig:
    """``use_verifier``: the AGENT reranking step (Table 2, "w/o AGENT reranking").
    ``use_attribute_heuristic``: decide between a "closest" query and a pure semantic one
    (Table 2, "w/o attribute heuristic"): with it, explicit proximity words and category-only
    instructions given a robot position become "closest" queries (eq. 17); without it every
    such instruction is ranked by caption similarity alone.
    ``use_predicates``: superlatives, relations and rooms read from the instruction."""

    use_verifier: bool = True
    use_attribute_heuristic: bool = True
    use_predicates: bool = True
    use_type_filter: bool = True  # candidates of the named category first, as the paper does for predicates
    top_k: int = 20  # candidates passed on to MMR and verification
    batch_size: int = 8  # objects per verification batch
    max_batches: int = 3
    use_mmr: bool = True
    mmr_lambda: float = 0.75  # relevance vs novelty
    min_score: float = 0.30  # "not found" below this cosine when not verifying
    grid_resolution: float = 0.05  # m, used when the map has no grid (eq. 17's s)
    runners_up: int = 5
    #: "not the yellow lamp": a negated colour names the instance(s) that fit it best, as a
    #: definite description does; candidates whose colour agreement is at least this share of the
    #: best one's are excluded too (a paler fit is "the other one": a light grey machine is not
    #: "the white washing machine" when a white one stands in the map).
    negation_contrast: float = 0.75
    #: How "closest" / "farthest" (to the robot or to a landmark) measure: "walking", along the
    #: map's floor (one Dijkstra per source), or "straight", the paper's eq. 17 grid distance.
    distance: str = "walking"

    def __post_init__(self) -> None:
        if self.distance not in ("walking", "straight"):
            raise InputError(f"distance must be 'walking' or 'straight', got {self.distance!r}")
        if self.top_k < 1 or self.batch_size < 1 or self.max_batches < 1:
            raise InputError("top_k, batch_size and max_batches must be >= 1")
        if not 0.0 <= self.mmr_lambda <= 1.0:
            raise InputError(f"mmr_lambda must be in [0, 1], got {self.mmr_lambda}")

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)
