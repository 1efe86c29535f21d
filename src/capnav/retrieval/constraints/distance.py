"""Distance to the robot (along the floor, or eq. 17's straight line): "the closest chair", "the
lamp farthest from me", and a bare category with a robot position (the paper's attribute
heuristic). It orders what no relation or superlative ordered (within the room, when one was named)."""

from __future__ import annotations

from capnav.retrieval.constraints.base import RankingConstraint, RankState, ranking
from capnav.retrieval.query import ParsedQuery


@ranking
class Distance(RankingConstraint):
    kind = "distance"
    order = 60

    @staticmethod
    def applies(q: ParsedQuery) -> bool:
        return True  # a bare category with a robot position is a "closest" query too

    def rank(self, st: RankState) -> None:
        q, cfg = st.q, st.r.config
        implicit = q.category_only and st.robot_xy is not None
        if not (cfg.use_attribute_heuristic and (q.proximity is not None or implicit)):
            return
        if st.predicate not in (None, "room"):
            return
        if st.robot_xy is None:
            st.notes.append(f"'{q.proximity}' needs a robot position (--robot X,Y); ranked by similarity instead")
            return
        full, kind = st.r.robot_distance(st.robot_xy, st.pool)  # the walk stops once the pool is measured
        d = full[st.pool]
        far = q.proximity == "farthest"
        st.group_keys.append(-d if far else d)
        st.values["walking distance to robot (m)" if kind == "walking" else "distance to robot (m)"] = d
        st.predicate, st.mode = ("farthest" if far else "closest"), "closest"
