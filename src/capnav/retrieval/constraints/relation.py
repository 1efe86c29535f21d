"""A landmark relation: "beside the fern", "between the bed and the wardrobe", "at the end of
the counter", "in the room with the green wardrobe", "the stool nearest the stove". The landmark is
resolved first (its colour, room or growth form picks the instance), then the candidates are
ordered by the relation's geometry in quarter-metre bins, so attributes break only near-ties."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError
from capnav.language.purpose import is_placing
from capnav.retrieval.constraints.base import RankingConstraint, RankState, ranking
from capnav.retrieval.query import ACROSS, BETWEEN, END_OF, ROOM_WITH, ParsedQuery, parse_instruction
from capnav.retrieval.spatial import end_distance, has_long_axis, segment_distance

BIN_M = 0.25  # distances closer than this are a tie on the relation
#: Relations of nearness to a landmark, met within the captions' "next to" (``next_to_distance``).
NEAR_RELATIONS = ("next to", "close to", "beside", "besides", "near", "by")
#: How much farther than "next to" a looser word of nearness reaches before a request is refused
#: for it (m): one bin of the order, the gap at which two candidates tie on the relation. "The lamp
#: near the bed" 1.3 m off is the lamp meant, "right beside" it is not; 1.5 m off is near neither
#: (the instruction generator's lookalikes stand a metre farther from the landmark than the target).
LOOSE_REACH = {"near": BIN_M}
#: Relations that put the target and the landmark in one room (walls between refuse them).
_SAME_ROOM_RELATIONS = {"next to", "close to", "beside", "besides", "near", "by", "alongside", "against",
                        "on top of", "above", "below", "underneath", "beneath", "under", "atop", "on"}
LEFT_OF, RIGHT_OF = "left of", "right of"


def landmarks(st: RankState, second: bool = False) -> NDArray[np.intp]:
    """The landmark's instances (the second landmark's of "between" with ``second``): of its
    category, and when its phrase says a colour, a room or a shape, only the instance(s) that fit
    best ("the yellow lamp", "the cactus")."""
    q = st.q
    category, phrase = (q.anchor2_category, q.anchor2_phrase) if second else (q.anchor_category, q.anchor_phrase)
    assert category is not None
    return landmark_instances(st, category, phrase)


def landmark_instances(st: RankState, category: str, phrase: str | None) -> NDArray[np.intp]:
    """The instances of ``category`` that a landmark's ``phrase`` ("the yellow lamp") picks."""
    r, notes = st.r, st.notes
    anchors = r.of_category(category)
    if len(anchors) < 2 or not phrase:
        return anchors
    try:
        aq = parse_instruction(phrase)
    except InputError:
        return anchors
    if aq.colors:
        agree = np.array([r.judge.color(aq, r.objects[k])[0] for k in anchors])
        keep = anchors[agree >= max(r.judge.config.color_reject, agree.max() - 0.05)]
        notes.append(f"landmark '{phrase}': object {', '.join(str(r.objects[k].id) for k in keep)}")
        anchors = keep
    if aq.room is not None:
        inroom = anchors[[r.scene.rooms[k] == aq.room for k in anchors]]
        anchors = inroom if len(inroom) else anchors
    if aq.shapes and len(anchors) > 1:
        # "beside the cactus": the plants whose points show the cactus's growth form.
        agree = np.array([r.judge.shape(aq, r.objects[k])[0] or 0.0 for k in anchors])
        if agree.max() > 0:
            anchors = anchors[agree >= agree.max()]
            notes.append(f"landmark '{phrase}': object {', '.join(str(r.objects[k].id) for k in anchors)}")
    if (aq.size_word or aq.superlative) and len(anchors) > 1:
        # "beside the bigger bed", "the lamp by the smallest table": the extreme instance of the
        # measure the word says (height for "tall", else volume), as the captions call them.
        measure = (r.scene.height if aq.size_axis == "height" else r.scene.volume)[anchors]
        if measure.max() > measure.min():
            large = (aq.superlative or aq.size_word) in ("large", "largest")
            anchors = anchors[[int(np.argmax(measure) if large else np.argmin(measure))]]
            notes.append(f"landmark '{phrase}': object {r.objects[int(anchors[0])].id}")
    return anchors


@ranking
class Relation(RankingConstraint):
    kind = "relation"
    order = 40

    @staticmethod
    def applies(q: ParsedQuery) -> bool:
        return (q.relation is not None or q.proximity_to_anchor) and q.anchor_category is not None

    def rank(self, st: RankState) -> None:
        r, q, pool = st.r, st.q, st.pool
        if not r.config.use_predicates:
            return
        anchors = landmarks(st)
        if not len(anchors):
            st.notes.append(f"no {q.anchor_category} in the map to be {q.relation}")
            return
        xy = r.scene.xy
        gap = r.scene.gap[np.ix_(pool, anchors)]
        same = pool[:, None] == anchors[None, :]
        gap = np.where(same, np.inf, gap).min(axis=1)
        st.values["gap to landmark (m)"] = gap
        regions = {int(r.scene.region[k]) for k in anchors} - {-1}
        if q.relation == ROOM_WITH and regions:
            # "the lamp in the room with the green wardrobe": the landmark's room region.
            same_room = np.array([int(r.scene.region[i]) in regions for i in pool], dtype=np.float64)
            st.group_keys.append(-same_room)
            st.predicate = f"{ROOM_WITH} the {q.anchor_category}"
            if not same_room.any():
                st.refuse(self.kind, f"no {q.category or q.target_phrase} stands in the room with the "
                                     f"{q.anchor_phrase}", override=False)
        elif q.relation == BETWEEN and q.anchor2_category is not None and len(second := landmarks(st, True)):
            # "the lamp between the bed and the wardrobe": distance to the segment joining
            # the two landmarks' centres (the best pair when there are several).
            line = np.array([min((segment_distance(xy[i], xy[a_], xy[b_]) for a_ in anchors for b_ in second
                                  if len({int(i), int(a_), int(b_)}) == 3), default=np.inf) for i in pool])
            st.values["distance to the line between the landmarks (m)"] = line
            st.group_keys.append(np.round(line / BIN_M))
            st.predicate = f"between the {q.anchor_category} and the {q.anchor2_category}"
        elif q.relation == ACROSS and q.anchor2_category is not None and len(mid := landmarks(st, True)):
            # "the armchair across the coffee table from the grey one": the object between lies
            # on the line from the landmark to the candidate (distance of its centre to it).
            line = np.array([min((segment_distance(xy[c], xy[i], xy[a_]) for a_ in anchors for c in mid
                                  if len({int(i), int(a_), int(c)}) == 3), default=np.inf) for i in pool])
            st.values["distance of the object between to the line (m)"] = line
            st.group_keys.append(np.round(line / BIN_M))
            st.predicate = f"across the {q.anchor2_category} from the {q.anchor_category}"
        elif q.relation == END_OF and len(long_ := np.array(
                [k for k in anchors if has_long_axis(r.objects[k].footprint)], dtype=np.intp)):
            # "the stool at the end of the counter": distance to the nearer end of the
            # landmark's long axis (a round or square landmark has no end: "next to").
            ends = np.array([min((end_distance(xy[i], r.objects[k].footprint) for k in long_ if k != i),
                                 default=np.inf) for i in pool])
            st.values["distance to the landmark's end (m)"] = ends
            st.group_keys.append(np.round(ends / BIN_M))
            st.predicate = f"{END_OF} the {q.anchor_category}"
        elif q.proximity_to_anchor and q.proximity is not None:
            # "the stool nearest the stove": distance to the landmark, exactly (along the
            # floor when the config says so: one Dijkstra from the landmarks' boxes).
            floor = r.floor_distances()
            walk = floor.from_objects(anchors)[pool] if floor is not None else None
            if walk is not None and np.isfinite(walk).any():
                centre = np.where(np.isin(pool, anchors), np.inf, np.where(np.isfinite(walk), walk, 1e6))
                st.values["walking distance to landmark (m)"] = centre
            else:
                centre = np.linalg.norm(xy[pool][:, None] - xy[anchors][None], axis=2)
                centre = np.where(same, np.inf, centre).min(axis=1)
            far = q.proximity == "farthest"
            st.group_keys.append(-centre if far else centre)
            st.predicate = f"{q.proximity} to the {q.anchor_category}"
        elif q.relation in (LEFT_OF, RIGHT_OF) and st.robot_xy is not None:
            # "the chair to the left of the desk", as the speaker sees it (from the robot): those
            # beside the landmark (within the captions' "next to") on that side of the line from
            # the robot through it first, then by the gap.
            near = anchors[np.argmin(np.where(same, np.inf, r.scene.gap[np.ix_(pool, anchors)]), axis=1)]
            view = xy[near] - np.asarray(st.robot_xy, dtype=np.float64)
            off = xy[pool] - xy[near]
            cross = view[:, 0] * off[:, 1] - view[:, 1] * off[:, 0]  # > 0: on the left
            on_side = (cross > 0) if q.relation == LEFT_OF else (cross < 0)
            beside = on_side & (gap <= r.scene.config.next_to_distance)
            st.values["on that side, seen from the robot"] = beside.astype(np.float64)
            st.group_keys.append(-beside.astype(np.float64))
            st.group_keys.append(np.round(gap / BIN_M))
            st.predicate = f"{q.relation} the {q.anchor_category}"
        else:
            if q.relation in (LEFT_OF, RIGHT_OF):
                st.notes.append(f"'{q.relation}' needs a viewpoint (a robot position): ordered by the gap "
                                f"to the {q.anchor_category} alone")
            key = np.round(gap / BIN_M)  # quarter-metre bins, attributes break ties
            if q.purpose is not None and (q.placing or is_placing(q.purpose)):
                # "somewhere by the bed to put my glass": every surface serves a thing put down,
                # so the landmark chooses among them before their order of fit (after a room).
                # Other purposes keep their order of fit first: their runners-up may merely allow
                # the activity, and standing near the landmark does not make them serve it.
                st.group_keys.insert(1 if q.room is not None else 0, key)
            else:
                st.group_keys.append(key)
            st.predicate = q.relation
            if q.relation in _SAME_ROOM_RELATIONS:
                self._walls_between(st, anchors, gap)
            if q.relation in NEAR_RELATIONS:
                # Ordered by the gap, the first would be taken however far it is: the only plant
                # left as "the plant beside the washer" three metres from any washer. Farther than
                # the captions' "next to" is said (``unmet``); farther than the word's reach (a loose
                # "near" reaches farther) is recorded, and when every candidate is, the query refuses.
                lim = float(r.scene.config.next_to_distance)
                reach = lim + LOOSE_REACH.get(q.relation, 0.0)
                for i, g in zip(pool.tolist(), gap.tolist(), strict=True):
                    if lim < g < math.inf:
                        st.unmet[int(i)] = (f"it stands {g:.1f} m from the nearest {q.anchor_category}, not "
                                            f"{q.relation} one (within {lim:.1f} m)")
                    if reach < g < math.inf:
                        st.out_of_reach[int(i)] = float(g)
                st.reach = reach
        st.mode = "predicate"

    def _walls_between(self, st: RankState, anchors: NDArray[np.intp], gap: NDArray[np.float64]) -> None:
        """"the sofa next to the bed" when every sofa stands in another room than every bed and
        farther from it than the captions' "next to": the walls the map observed say no candidate
        is near the landmark, so it is refused (a room region of -1, walls unknown there, is no
        evidence either way; one room cut in two regions keeps its close pairs)."""
        r, q, pool = st.r, st.q, st.pool
        reg = r.scene.region
        known_anchor = [int(reg[k]) for k in anchors if int(reg[k]) >= 0]
        if not len(pool) or len(known_anchor) < len(anchors):
            return
        far = r.scene.config.next_to_distance
        apart = [int(reg[i]) >= 0 and int(reg[i]) not in known_anchor and g > far
                 for i, g in zip(pool, gap, strict=True)]
        if all(apart):
            what = q.category or q.target_phrase
            st.refuse(self.kind, f"no {what} stands {q.relation} the {q.anchor_phrase or q.anchor_category}: "
                                 "walls stand between every one and it", override=False)
