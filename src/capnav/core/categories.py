"""The object vocabulary shared by the simulator, the detectors and the evaluation.

A real open-vocabulary detector is also run with a vocabulary (Detic's custom vocabulary), so
the mapping pipeline knowing these names is not a leak of scene truth. Category ids start at 1;
0 is background. ``CONFUSION_GROUPS`` are the lookalike categories a detector mixes up.
"""

from __future__ import annotations

from dataclasses import dataclass

from capnav.core.errors import InputError


@dataclass(frozen=True)
class Category:
    id: int
    name: str
    synonyms: tuple[str, ...] = ()


_SPEC: list[tuple[str, tuple[str, ...]]] = [
    ("sofa", ("couch", "settee", "sectional")),
    ("armchair", ("easy chair", "lounge chair", "accent chair")),
    ("chair", ("dining chair", "seat", "side chair")),
    ("stool", ("bar stool", "tabouret")),
    ("table", ("dining table", "kitchen table")),
    ("coffee table", ("low table", "cocktail table")),
    ("desk", ("writing desk", "work desk", "computer desk")),
    ("bed", ("double bed", "single bed")),
    ("nightstand", ("bedside table", "night table")),
    ("wardrobe", ("closet", "armoire")),
    ("dresser", ("chest of drawers", "bureau")),
    ("cabinet", ("cupboard", "sideboard")),
    ("bookshelf", ("bookcase", "shelf", "shelving unit")),
    # The COCO class is PASCAL VOC's "tvmonitor": a monitor or a screen is the class (WordNet has both
    # words as other things first: a proctor, a projection screen).
    ("tv", ("television", "tv screen", "telly", "monitor", "screen", "tv monitor")),
    ("lamp", ("floor lamp", "standing lamp")),
    ("plant", ("potted plant", "houseplant", "pot plant")),
    ("toilet", ("wc", "loo")),
    ("sink", ("washbasin", "basin")),
    ("bathtub", ("tub", "bath")),
    ("refrigerator", ("fridge", "freezer")),
    ("counter", ("countertop", "kitchen counter", "worktop")),
    ("stove", ("oven", "cooker", "range")),
    ("washing machine", ("washer", "laundry machine")),
    ("ottoman", ("footstool", "pouf", "pouffe")),
]

CATEGORIES: tuple[Category, ...] = tuple(Category(i + 1, n, s) for i, (n, s) in enumerate(_SPEC))
NAMES: tuple[str, ...] = tuple(c.name for c in CATEGORIES)
BY_NAME: dict[str, Category] = {c.name: c for c in CATEGORIES}
BY_ID: dict[int, Category] = {c.id: c for c in CATEGORIES}

#: Lookalike groups: a detector's label confusion stays inside a group.
CONFUSION_GROUPS: tuple[tuple[str, ...], ...] = (
    ("chair", "armchair", "stool"),
    ("sofa", "armchair"),
    ("table", "desk", "coffee table"),
    ("cabinet", "bookshelf", "dresser", "wardrobe", "nightstand"),
    ("counter", "cabinet"),
    ("sink", "bathtub"),
    ("ottoman", "stool"),
    ("refrigerator", "wardrobe"),
)


def category(name_or_id: str | int) -> Category:
    """Look a category up by name, synonym or id; raise ``InputError`` listing the valid names."""
    if isinstance(name_or_id, int):
        if name_or_id in BY_ID:
            return BY_ID[name_or_id]
        raise InputError(f"unknown category id {name_or_id}; valid ids are 1..{len(CATEGORIES)}")
    key = name_or_id.strip().lower().replace("_", " ")
    if key in BY_NAME:
        return BY_NAME[key]
    for c in CATEGORIES:
        if key in c.synonyms:
            return c
    raise InputError(f"unknown category {name_or_id!r}; known: {', '.join(NAMES)}")


def confusable(name: str) -> tuple[str, ...]:
    """Categories a detector may confuse ``name`` with (excluding itself)."""
    out: list[str] = []
    for group in CONFUSION_GROUPS:
        if name in group:
            out.extend(g for g in group if g != name and g not in out)
    return tuple(out)
