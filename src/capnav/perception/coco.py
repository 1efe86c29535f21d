"""The COCO-80 vocabulary of the closed-set real detectors and how it maps onto CapNav's categories.

COCO classes that name a CapNav category get that category's id and name (``couch`` -> ``sofa``,
``dining table`` -> ``table``, ``potted plant`` -> ``plant``, ``oven`` -> ``stove``, ...), so a
real detector's output means the same as the simulator detector's. Other indoor things a person
may ask for (``vase``, ``book``, ``clock``, ``laptop``, ``bottle``, ``bench``...) keep their COCO
name with ``class_id`` 0, so they are mapped, captioned and can be queried by name. Classes that
move (people, animals), belong outdoors (vehicles, street furniture, sports gear) or are food and
cutlery are dropped by default: they are not landmarks of a room map. ``classes="all"`` keeps
every class; a list of COCO names keeps exactly those.
"""

from __future__ import annotations

from collections.abc import Sequence

from capnav.core.categories import category
from capnav.core.errors import InputError

#: The 80 COCO detection classes in the models' output order (class index 0..79).
COCO80: tuple[str, ...] = (
    "person", "bicycle", "car", "motorcycle", "airplane", "bus", "train", "truck", "boat", "traffic light",
    "fire hydrant", "stop sign", "parking meter", "bench", "bird", "cat", "dog", "horse", "sheep", "cow",
    "elephant", "bear", "zebra", "giraffe", "backpack", "umbrella", "handbag", "tie", "suitcase", "frisbee",
    "skis", "snowboard", "sports ball", "kite", "baseball bat", "baseball glove", "skateboard", "surfboard",
    "tennis racket", "bottle", "wine glass", "cup", "fork", "knife", "spoon", "bowl", "banana", "apple",
    "sandwich", "orange", "broccoli", "carrot", "hot dog", "pizza", "donut", "cake", "chair", "couch",
    "potted plant", "bed", "dining table", "toilet", "tv", "laptop", "mouse", "remote", "keyboard",
    "cell phone", "microwave", "oven", "toaster", "sink", "refrigerator", "book", "clock", "vase", "scissors",
    "teddy bear", "hair drier", "toothbrush",
)

#: COCO name -> CapNav category name (each resolves through ``capnav.core.categories.category``).
TO_CAPNAV: dict[str, str] = {
    "chair": "chair",
    "couch": "sofa",
    "bed": "bed",
    "dining table": "table",
    "toilet": "toilet",
    "tv": "tv",
    "potted plant": "plant",
    "sink": "sink",
    "refrigerator": "refrigerator",
    "oven": "stove",
}

#: Indoor COCO classes kept under their own name (class_id 0) in the default ``classes="indoor"``.
KEPT_AS_IS: tuple[str, ...] = (
    "bench", "backpack", "umbrella", "handbag", "suitcase", "bottle", "wine glass", "cup", "bowl", "laptop",
    "mouse", "remote", "keyboard", "cell phone", "microwave", "toaster", "book", "clock", "vase", "scissors",
    "teddy bear", "hair drier", "toothbrush",
)

CLASS_SETS = ("indoor", "all")


def coco_label(name: str) -> tuple[int, str]:
    """(class_id, label) of a COCO class: the CapNav category when mapped, else (0, the COCO name)."""
    if name not in COCO80:
        raise InputError(f"{name!r} is not a COCO-80 class")
    target = TO_CAPNAV.get(name)
    if target is None:
        return 0, name
    c = category(target)
    return c.id, c.name


def class_table(classes: str | Sequence[str] = "indoor") -> list[tuple[int, str] | None]:
    """Per COCO index, its (class_id, label), or None when the class is dropped.

    ``classes``: ``"indoor"`` (the mapped categories plus ``KEPT_AS_IS``), ``"all"``, or a list
    (or comma-separated text) of COCO names to keep.
    """
    if isinstance(classes, str) and classes in CLASS_SETS:
        keep = set(COCO80) if classes == "all" else set(TO_CAPNAV) | set(KEPT_AS_IS)
    else:
        items = classes.split(",") if isinstance(classes, str) else list(classes)
        names = [str(c).strip() for c in items if str(c).strip()]
        unknown = [n for n in names if n not in COCO80]
        if unknown or not names:
            raise InputError(f"classes must be 'indoor', 'all' or COCO-80 names; unknown: {unknown or classes!r} "
                             f"(e.g. chair, couch, dining table, potted plant, tv, book, vase)")
        keep = set(names)
    return [coco_label(n) if n in keep else None for n in COCO80]
