"""What a map's detector could name: its closed vocabulary (``meta["detector_labels"]``, or its
COCO detector's id for maps made before that was recorded), the classes a category without a
class of its own is kept under, and whether an object of such a class stands at the category's
working height. Shared by the category and the detectable constraints."""

from __future__ import annotations

from typing import Any

_COCO_BACKENDS = ("yolo-fastest:", "centernet:", "coco:")


def detector_labels(meta: dict[str, Any]) -> frozenset[str] | None:
    """The labels the map's detector could output, or None when any category could come out
    (the simulator's detector, an open vocabulary, a map that does not say)."""
    if "detector_labels" in meta:
        return frozenset(str(x) for x in meta["detector_labels"])
    det = str(meta.get("detector", ""))
    if det.startswith(_COCO_BACKENDS):
        classes = next((p.split("=", 1)[1] for p in det.split(":") if p.startswith("classes=")), None)
        if classes in ("indoor", "all"):
            from capnav.perception.coco import class_table

            return frozenset(t[1] for t in class_table(classes) if t is not None)
    return None


def coarser_classes(cmap: Any, category: str) -> set[str]:
    """The classes of the map's detector that ``category`` is a kind of, when it has no class of
    its own (a COCO model's "chair" holds armchairs, its "dining table" coffee tables): where such
    a map keeps the category's instances. Empty when the detector could name it, or when the map
    does not say what its detector can name."""
    labels = detector_labels(getattr(cmap, "meta", {}) or {})
    if labels is None or category in labels:
        return set()
    from capnav.language.lexicon import load_lexicon

    rel = load_lexicon().relations
    return {p for p in labels if rel.get(p, {}).get(category, {}).get("kind_of")}


def height_fits(obj: Any, category: str, tol: float = 0.1) -> bool:
    """Whether the object's top is at ``category``'s working height (``corroborate.PRIORS``), or
    the category has no such prior (nothing to contradict)."""
    from capnav.mapping.corroborate import PRIORS

    prior = PRIORS.get(category)
    if prior is None:
        return True
    top = float(obj.extent_max[2])
    return prior.z_lo - tol <= top <= prior.z_hi + tol
