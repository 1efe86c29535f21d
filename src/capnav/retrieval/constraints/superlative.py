"""A superlative of size ("the biggest armchair"): the mapped volume orders the candidates; of
height ("the tallest lamp", "the lowest table"), the mapped height; of width ("the widest
wardrobe", "the narrowest bookcase"), the footprint's longer side."""

from __future__ import annotations

from capnav.retrieval.constraints.base import RankingConstraint, RankState, ranking
from capnav.retrieval.query import ParsedQuery


@ranking
class Superlative(RankingConstraint):
    kind = "superlative"
    order = 50

    @staticmethod
    def applies(q: ParsedQuery) -> bool:
        return q.superlative is not None

    def rank(self, st: RankState) -> None:
        if not st.r.config.use_predicates:
            return
        if st.q.size_axis == "height":
            vol, what = st.r.scene.height[st.pool], "height (m)"
        elif st.q.size_axis == "width":
            vol, what = st.r.scene.width[st.pool], "width (m)"
        else:
            vol, what = st.r.volume[st.pool], "volume (m3)"
        st.group_keys.append(-vol if st.q.superlative == "largest" else vol)
        st.values[what] = vol
        st.predicate, st.mode = st.q.superlative, "predicate"
