"""The room ("the stool in the study"): inferred from the objects around each candidate, never
observed, so it orders (the named room, then no inferred room, then the strength of its cues) and
refuses only where the evidence against it is confident."""

from __future__ import annotations

import numpy as np

from capnav.core.text import agree, join, of_them, plural
from capnav.language.context import HALLWAY, ROOM_CUES
from capnav.retrieval.constraints.base import (
    CONTRADICTED,
    SUPPORTED,
    UNOBSERVED,
    Evidence,
    RankingConstraint,
    RankState,
    ranking,
)
from capnav.retrieval.query import ParsedQuery

_ROOMS = list(ROOM_CUES)


@ranking
class Room(RankingConstraint):
    kind = "room"
    order = 30

    @staticmethod
    def applies(q: ParsedQuery) -> bool:
        return q.room is not None

    def rank(self, st: RankState) -> None:
        q, r = st.q, st.r
        assert q.room is not None
        judged = r.config.use_predicates and len(st.pool) > 0
        if judged and q.room in _ROOMS:
            self._typed(st, q.room)
        elif judged and q.room == HALLWAY:
            self._hallway(st)
        elif q.room not in _ROOMS:
            st.notes.append(f"rooms of type '{q.room}' are not inferred from the map; the room was not used")

    def _typed(self, st: RankState, room: str) -> None:
        q, r, pool = st.q, st.r, st.pool
        rooms = [r.scene.rooms[i] for i in pool]
        in_room = np.array([x == room for x in rooms], dtype=np.float64)
        # A candidate where no room was inferred is unobserved, unless the map has the named room
        # elsewhere: a region typed kitchen says where the kitchen is, so a stool in an untyped
        # region (a hallway) is evidence against "the kitchen stool".
        elsewhere = any(x == room for x, _ in r.scene.region_rooms.values())
        unknown = np.array([x is None and not (elsewhere and int(r.scene.region[i]) >= 0)
                            for x, i in zip(rooms, pool, strict=True)], dtype=np.float64)
        strength = r.scene.room_score[pool, _ROOMS.index(room)]
        for k, i in enumerate(pool):
            status = SUPPORTED if in_room[k] else UNOBSERVED if unknown[k] else CONTRADICTED
            seen = f"inferred room {rooms[k] or 'none'}"
            st.report(self.kind, int(i), Evidence(self.kind, status, float(strength[k]), seen))
        # Inferred room first, then objects of no inferred room, then the strength of the cues.
        st.group_keys.insert(0, -(2 * in_room + unknown))  # the room before the category tier
        if q.room_colors and in_room.any():
            coloured = self._coloured_room(st, room)
            if coloured is not None:
                st.group_keys.insert(1, -coloured)
        st.order_keys.append(-strength)
        st.values["room cue"] = strength
        st.predicate, st.mode = "room", "predicate"
        n = int(in_room.sum())
        st.notes.append(f"{of_them(n, 'appears')} to be in the {room} (inferred from nearby objects)")
        # A room is inferred, never observed: refuse only where the evidence against the named
        # room is confident, i.e. no candidate of the best category tier has a cue of it in its
        # own room (a wardrobe beside the desk of a room typed "office" by that desk says
        # "bedroom" too). Weak evidence serves the named object, not a substitute for it.
        top = st.weights[pool] >= st.weights[pool].max()
        possible = (strength >= r.scene.config.room_min_score) & top
        if not in_room.any() and not unknown.any() and not possible.any():
            where = join(f"the {x}" for x in sorted({str(x) for x in rooms}))
            what = q.category or q.target_phrase
            noun = what if all(r.cats[int(i)] == q.category for i in pool) else "candidate"
            n = len(pool)
            st.refuse(self.kind, f"no {what} stands in the {room}; "
                                 f"the {plural(noun) if n > 1 else noun} {agree(n, 'is')} in {where}")
        elif not in_room.any() and possible.any():
            k = int(np.argmax(strength))
            st.notes.append(f"none is inferred to be in the {room}, but object {r.objects[pool[k]].id} "
                            f"({r.scene.rooms[pool[k]]}) has {room} cues where it stands ({strength[k]:.2f})")
        elif in_room.any():
            # The map shows where the named room is and candidates stand in it: one that stands
            # elsewhere, with no cue of the room where it stands, is evidence against, not a
            # fallback for when those in the room are refused ("the cactus in the office" is not
            # the hallway's cactus once the office's plant is no cactus).
            away = (in_room == 0) & (unknown == 0) & (strength < r.scene.config.room_min_score)
            if away.any():
                st.notes.append(f"left out, standing outside the {room}: "
                                + ", ".join(f"object {r.objects[i].id} ({r.scene.rooms[i] or 'a room of no type'})"
                                            for i in pool[away]))
                st.keep(~away)

    @staticmethod
    def _coloured_room(st: RankState, room: str) -> np.ndarray | None:
        """Per pool member, 1 when it stands in the one region of type ``room`` that holds the
        object best fitting the room's colours ("the yellow bedroom": the yellow bed's), when that
        fit is plausible and no other such region holds as good a one; else None (a note says so)."""
        q, r, pool = st.q, st.r, st.pool
        said = ParsedQuery(text=" ".join(q.room_colors), colors=list(q.room_colors))
        best: dict[int, float] = {}
        for k, obj in enumerate(r.objects):
            g = int(r.scene.region[k])
            if g < 0 or r.scene.region_rooms.get(g, (None, {}))[0] != room:
                continue
            best[g] = max(best.get(g, 0.0), r.judge.color_fit(said, obj)[1])
        ranked = sorted(best.items(), key=lambda kv: -kv[1])
        colour = "/".join(q.room_colors)
        if not ranked or ranked[0][1] < r.judge.config.color_reject or (
                len(ranked) > 1 and ranked[1][1] >= ranked[0][1] - 1e-6):
            st.notes.append(f"no one {room} holds a {colour} object apart from the others; the colour was not used")
            return None
        region = ranked[0][0]
        st.notes.append(f"the {colour} {room} is the one holding the {colour} object")
        return np.array([int(r.scene.region[i]) == region for i in pool], dtype=np.float64)

    def _hallway(self, st: RankState) -> None:
        # A hallway has no characteristic objects: objects of a region without any room's cues
        # first, then the weakest cues of any room. No refusal: an untyped region is weak evidence.
        r, pool = st.r, st.pool
        untyped = np.array([r.scene.rooms[i] is None for i in pool], dtype=np.float64)
        weakest = -r.scene.room_score[pool].max(axis=1)
        st.group_keys.insert(0, -untyped)
        st.order_keys.append(-weakest)
        st.values["no room cue"] = weakest
        st.predicate, st.mode = "room", "predicate"
        n = int(untyped.sum())
        st.notes.append(f"{of_them(n, 'stands')} where no room's objects are (a hallway)")
