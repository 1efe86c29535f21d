"""Which room a region is, from what stands in it, and how sure that is.

A sink alone says nothing certain (kitchens and bathrooms both have one); a sink with a stove, a
fridge or a counter is a kitchen, a sink with a toilet or a bathtub a bathroom. ``room_posterior``
is a naive-Bayes posterior over room types given the categories *present* in a region (absence
is no evidence: detectors miss things, and a region is rarely seen whole), with a uniform prior
over the types; ``ROOM_PRIOR`` gives P(category present | room type). Below
``ContextConfig.room_confidence`` the region has no room type: a caption says nothing about the
room rather than a wrong one.

Source of the table: round figures for how often each category is annotated in scenes of each
type in the public scene datasets' statistics (SUN RGB-D's 19 common scene types, Song et al.,
CVPR 2015; ScanNet v2's scene types, Dai et al., CVPR 2017): a toilet in nearly every bathroom
and almost nowhere else, a sink in most kitchens and bathrooms, a bed in nearly every bedroom, a
sofa in most living rooms, a desk in most offices. They are estimates rounded to the nearest
5-10%, written here from those statistics' published summaries, not counts recomputed from the
datasets; categories a type is not listed with get ``FLOOR`` (a bed in a kitchen happens, but
rarely). Categories that stand anywhere (plants, lamps, cabinets, ottomans) carry no evidence.
"""

from __future__ import annotations

from collections.abc import Iterable

#: P(category present | room type), rounded; see the module docstring for the source.
ROOM_PRIOR: dict[str, dict[str, float]] = {
    "kitchen": {"refrigerator": 0.9, "stove": 0.85, "counter": 0.9, "sink": 0.8, "table": 0.5, "chair": 0.6,
                "stool": 0.3, "washing machine": 0.2},
    "bathroom": {"toilet": 0.9, "sink": 0.9, "bathtub": 0.5, "washing machine": 0.25, "counter": 0.3},
    "bedroom": {"bed": 0.95, "nightstand": 0.7, "wardrobe": 0.5, "dresser": 0.5, "tv": 0.25, "desk": 0.2,
                "chair": 0.2, "armchair": 0.15},
    "living room": {"sofa": 0.9, "tv": 0.7, "coffee table": 0.7, "armchair": 0.5, "bookshelf": 0.3, "table": 0.3,
                    "chair": 0.3},
    "office": {"desk": 0.9, "chair": 0.8, "bookshelf": 0.5, "sofa": 0.1, "armchair": 0.15, "table": 0.1,
               "wardrobe": 0.1},
    # SUN RGB-D's "corridor": storage furniture now and then, no room's own furniture.
    "hallway": {"wardrobe": 0.2, "dresser": 0.2, "washing machine": 0.1, "bookshelf": 0.1},
}
#: P(present | room type) of a category the type is not listed with.
FLOOR = 0.02
#: Categories that stand in any room: they say nothing about which.
NEUTRAL = frozenset({"plant", "lamp", "cabinet", "ottoman"})


def evidence(labels: Iterable[str]) -> list[str]:
    """The distinct categories among ``labels`` that speak for some room type."""
    cues = {c for likes in ROOM_PRIOR.values() for c in likes}
    return sorted({lab for lab in labels if lab in cues and lab not in NEUTRAL})


def room_posterior(labels: Iterable[str]) -> dict[str, float]:
    """P(room type | the categories present), uniform prior; all zero when nothing speaks for a room."""
    present = evidence(labels)
    if not present:
        return dict.fromkeys(ROOM_PRIOR, 0.0)
    like = {room: 1.0 for room in ROOM_PRIOR}
    for room, table in ROOM_PRIOR.items():
        for c in present:
            like[room] *= table.get(c, FLOOR)
    total = sum(like.values())
    return {room: v / total for room, v in like.items()}


def best_room(labels: Iterable[str], confidence: float) -> tuple[str | None, float]:
    """(room type, its posterior) when the posterior reaches ``confidence``, else (None, it)."""
    post = room_posterior(labels)
    room, p = max(post.items(), key=lambda kv: (kv[1], kv[0]))
    return (room if p >= confidence and p > 0 else None), p
