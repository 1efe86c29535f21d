"""What the map's detector can see: a request for a category its closed vocabulary lacks (a
cabinet, for a COCO model) is "not found" because the map cannot contain one, which is not the
same answer as "there is none". The vocabulary is the map's ``meta["detector_labels"]``; maps made
before it was recorded give it through their COCO detector's id (``classes=indoor|all``)."""

from __future__ import annotations

from typing import Any

from capnav.core.text import plural
from capnav.retrieval.constraints.base import RankingConstraint, RankState, ranking
from capnav.retrieval.query import ParsedQuery

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


@ranking
class Detectable(RankingConstraint):
    kind = "detectable"
    order = 15  # after the category set the pool up, before anything orders it

    @staticmethod
    def applies(q: ParsedQuery) -> bool:
        return q.category is not None and q.purpose is None

    def rank(self, st: RankState) -> None:
        r, q = st.r, st.q
        assert q.category is not None
        if len(r.of_category(q.category)):
            return
        labels = detector_labels(getattr(r.cmap, "meta", {}) or {})
        if labels is None or q.category in labels:
            return
        det = str(r.cmap.meta.get("detector", "the detector")).split(":")[0]
        held = sorted(coarser_classes(r.cmap, q.category) & {r.cats[int(i)] for i in st.pool})
        if held:
            st.notes.append(f"the map's detector ({det}) has no '{q.category}' class: "
                            f"{' and '.join(plural(h) for h in held)} are what it calls "
                            f"{plural(q.category)}, so they are looked at")
            return
        why = (f"the map's detector ({det}) has no '{q.category}' class, so the map cannot contain "
               f"{'an' if q.category[:1] in 'aeiou' else 'a'} {q.category}")
        # Refused unless a stand-in the request admits is in the map (a table for "the desk"): with
        # none, every object was pooled only to be compared, and none of them can be the category
        # the detector has no class for.
        from capnav.retrieval.constraints.category import Category

        named = Category.weights(st)
        if st.refusal is not None or not len(st.pool) or not (named[st.pool] > 0).any():
            st.refuse(self.kind, why)
        else:
            st.notes.append(why)
