"""What the map's detector can see: a request for a category its closed vocabulary lacks (a
cabinet, for a COCO model) is "not found" because the map cannot contain one, which is not the
same answer as "there is none". The vocabulary is the map's ``meta["detector_labels"]``; maps made
before it was recorded give it through their COCO detector's id (``classes=indoor|all``)."""

from __future__ import annotations

from capnav.core.text import plural
from capnav.retrieval.constraints.base import RankingConstraint, RankState, ranking
from capnav.retrieval.constraints.classes import coarser_classes, detector_labels
from capnav.retrieval.query import ParsedQuery

__all__ = ["Detectable", "detector_labels"]


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
