"""A request by purpose ("somewhere to put my feet up"): the categories that serve the activity,
best fit first (``language.purpose``: the furniture made for it before what merely allows it),
are the category tiers; this constraint says the order in the reason and leaves a purpose whose
best category is absent to the ones after it. The room the activity implies (``purpose_room``:
"before making tea", the kitchen) orders the instances within a tier: the kitchen sink before
the bathroom sink. It is a preference, never a refusal: a sink elsewhere still serves."""

from __future__ import annotations

import numpy as np

from capnav.retrieval.constraints.base import RankingConstraint, RankState, ranking
from capnav.retrieval.query import ParsedQuery


@ranking
class Purpose(RankingConstraint):
    kind = "purpose"
    order = 12  # after the category set the tiers up

    @staticmethod
    def applies(q: ParsedQuery) -> bool:
        return q.purpose is not None and q.category is not None

    def rank(self, st: RankState) -> None:
        q, r = st.q, st.r
        present = {r.cats[int(i)] for i in st.pool}
        fit = [(1.0, str(q.category)), *sorted(((w, c) for c, w in q.category_alternatives.items()), reverse=True)]
        served = [f"{c}" + ("" if w >= 1.0 else f" ({w:.2f})") for w, c in fit if c in present]
        if served:
            st.notes.append(f"'{q.purpose}' is served best by {', then '.join(served[:4])}")
        if q.purpose_room is not None and q.room is None and q.anchor_category is None and len(st.pool):
            in_room = np.array([r.scene.rooms[int(i)] == q.purpose_room for i in st.pool], dtype=np.float64)
            if in_room.any() and not in_room.all():
                st.group_keys.append(-in_room)  # after the category tier: which of its instances
                if st.mode == "semantic":
                    st.predicate, st.mode = f"in the {q.purpose_room}, where '{q.purpose}' is done", "predicate"
                st.notes.append(f"'{q.purpose}' is done in the {q.purpose_room}: "
                                f"{int(in_room.sum())} of the candidates stand there")
