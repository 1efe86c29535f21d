"""An ordinal ("the second closest lamp"): the n-th in the order a predicate gave, so the first
n - 1 are passed over. Without a predicate there is no order to count in."""

from __future__ import annotations

from capnav.retrieval.constraints.base import SORT_AT, RankingConstraint, RankState, ranking
from capnav.retrieval.query import ParsedQuery

_ORDINALS = {2: "second", 3: "third", 4: "fourth", 5: "fifth"}


def ordinal_word(n: int) -> str:
    return _ORDINALS.get(n, str(n))


@ranking
class Ordinal(RankingConstraint):
    kind = "ordinal"
    order = SORT_AT + 10

    @staticmethod
    def applies(q: ParsedQuery) -> bool:
        return q.ordinal is not None and q.ordinal > 1

    def rank(self, st: RankState) -> None:
        n = st.q.ordinal
        assert n is not None
        if st.mode == "semantic" or not len(st.order):
            return
        skip = st.order[: n - 1]
        st.notes.append(f"'{ordinal_word(n)}': passed over " + ", ".join(f"object {st.r.objects[i].id}" for i in skip))
        st.order, st.groups = st.order[n - 1:], st.groups[n - 1:]
