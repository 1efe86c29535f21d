"""A negation ("not the white one", "the wardrobe that isn't white"): the candidates it names
leave the pool; when it leaves no other one of the named category, "not found"."""

from __future__ import annotations

import numpy as np

from capnav.core.errors import InputError
from capnav.language.offline_captioner import GROWING
from capnav.retrieval.constraints.base import CONTRADICTED, Evidence, RankingConstraint, RankState, ranking
from capnav.retrieval.constraints.relation import BIN_M, landmark_instances
from capnav.retrieval.query import ParsedQuery, parse_instruction
from capnav.retrieval.query.mapping import negated_relation


def readings(q: ParsedQuery) -> dict[str, ParsedQuery]:
    """Each negated phrase read as a request of its own ("not the red lamp in the lounge": a red
    lamp, in the lounge), once per query; a relation ("not beside the bed") or a phrase that does
    not read is left out."""
    out: dict[str, ParsedQuery] = {}
    for phrase in q.negations:
        if phrase in out or negated_relation(phrase) is not None:
            continue
        try:
            out[phrase] = parse_instruction(phrase)
        except InputError:
            continue
    return out


@ranking
class Negation(RankingConstraint):
    kind = "negation"
    order = 20

    @staticmethod
    def applies(q: ParsedQuery) -> bool:
        return bool(q.negations)

    def rank(self, st: RankState) -> None:
        if not len(st.pool):
            return
        q, r = st.q, st.r
        read = readings(q)
        neg = self.excluded(st, read)
        if not neg:
            return
        st.notes.append("excluded by the negation: " + ", ".join(
            f"object {r.objects[i].id} ({neg[i]})" for i in neg))
        for i, phrase in neg.items():
            st.report(self.kind, i, Evidence(self.kind, CONTRADICTED, 0.0, f"it is what '{phrase}' excludes"))
        had_named = bool((st.weights[st.pool] >= 1.0).any())
        st.keep(np.array([int(i) not in neg for i in st.pool], dtype=bool))
        self.share_room(st, read)
        if not len(st.pool) or (had_named and not (st.weights[st.pool] >= 1.0).any()):
            # "not the black stove, the other one" presumes another of that category: an
            # alternative category ("a fridge can serve as a washer") is no "other one".
            st.refuse(self.kind, f"every {q.category or 'candidate'} matches what the instruction excludes "
                                 f"({'; '.join(q.negations)})")

    @staticmethod
    def share_room(st: RankState, read: dict[str, ParsedQuery]) -> None:
        """"not the red lamp in the lounge, the other one": a negation that tells its object apart by
        an attribute and says the room it stands in puts the one asked for in that room too (the
        contrast is the attribute), when the request says no room of its own and another candidate
        of the named category stands there. A negation whose only distinction is the room ("the lamp
        that isn't in the lounge") sends the answer elsewhere, as before."""
        q, r = st.q, st.r
        if q.room is not None or not len(st.pool):
            return
        for phrase, nq in read.items():
            if nq.room is None or not (nq.colors or nq.materials or nq.shapes or nq.size_word):
                continue
            there = np.array([r.scene.rooms[int(i)] == nq.room for i in st.pool], dtype=bool)
            if (there & (st.weights[st.pool] >= 1.0)).any():
                st.keep(there)
                st.notes.append(f"the {nq.room} of '{phrase}' is where the other one stands too")
            return

    @staticmethod
    def _colour_names(st: RankState, nq: ParsedQuery, ref: np.ndarray) -> np.ndarray:
        """Which pool members a negated colour names. A growing category (a plant) is told apart by
        its pot, its foliage being alike: there the colour is judged on the bases' colours when they
        name some of ``ref`` but not all ("not the red one" among green-leaved plants is the one in
        the red pot); otherwise, and for every other category, on the whole objects' colours."""
        r, pool = st.r, st.pool

        def names(base: bool | None) -> np.ndarray:
            col = {int(i): r.judge.color(nq, r.objects[int(i)], base=base)[0] for i in pool}
            best = max((col[int(i)] for i in ref), default=0.0)
            bar = max(r.judge.config.color_reject, r.config.negation_contrast * best)
            return np.array([col[int(i)] >= bar for i in pool], dtype=bool)

        if st.q.category in GROWING:
            in_ref = np.isin(pool, ref)
            bases = names(True)
            if 0 < int(bases[in_ref].sum()) < int(in_ref.sum()):
                return bases
        return names(None)

    @staticmethod
    def excluded(st: RankState, read: dict[str, ParsedQuery]) -> dict[int, str]:
        """Candidates of the pool a negation names, with the phrase (``read``: the phrases' own
        readings, ``readings``).

        A negated colour is read as a definite description among the candidates: it names the
        ones that fit it best (agreement at least ``color_reject``, and at least
        ``negation_contrast`` of the best fit among the named category's candidates), not every
        candidate that is somewhat that colour; so "not the red armchair, the other one" excludes
        the mustard lamp although its agreement is below ``color_match``, and "not the white
        washing machine" keeps the light grey one when a white one stands beside it."""
        r, q, pool, weights = st.r, st.q, st.pool, st.weights
        out: dict[int, str] = {}
        named = pool[weights[pool] >= 1.0]
        ref = named if len(named) else pool
        for phrase in q.negations:
            rel = negated_relation(phrase)
            if rel is not None:
                # "the lamp that's not beside the bed" presumes one is: the candidates nearest
                # to the landmark (the relation's quarter-metre bin) are that one.
                anchors = landmark_instances(st, rel[1], rel[2])
                if len(anchors):
                    gap = np.where(pool[:, None] == anchors[None, :], np.inf, r.scene.gap[np.ix_(pool, anchors)])
                    g = gap.min(axis=1)
                    if np.isfinite(g).any():
                        for i in pool[g <= g.min() + BIN_M]:
                            out.setdefault(int(i), phrase)
                continue
            nq = read.get(phrase)
            if nq is None:
                continue
            if nq.category is not None and nq.category != q.category and not nq.colors and not nq.room:
                if nq.category in q.category_alternatives and not nq.has_attributes:
                    # "not either of the desks, the cabinet": a negated category never answers
                    # while another candidate fits, not even as a stand-in.
                    for i in pool[r.cats_arr[pool] == nq.category]:
                        out.setdefault(int(i), phrase)
                continue  # "not the one at the end of the counter": a relation this reader does not judge
            fits = np.ones(len(pool), dtype=bool)
            judged = False
            if nq.category is not None and nq.category == q.category:
                fits &= r.cats_arr[pool] == nq.category
                judged = True
            if nq.colors:
                fits &= Negation._colour_names(st, nq, ref)
                judged = True
            if nq.room is not None:
                fits &= np.array([r.scene.rooms[int(i)] == nq.room for i in pool])
                judged = True
            if nq.shapes:
                fits &= np.array([all(w.lower() in (r.objects[int(i)].caption or "").lower() for w in nq.shapes)
                                  for i in pool])
                judged = True
            if nq.materials:
                # "the ottoman that isn't velvet" presumes a velvet one: those whose pixels show it
                # (evidence supported) are excluded; when none shows it but some show a surface
                # against it, those are the ones that are not, and the unobserved ones go instead.
                mat = [r.judge.material(nq, r.objects[int(i)])[0] for i in pool]
                shows = np.array([m is not None and m >= 1.0 for m in mat])
                against = np.array([m is None for m in mat])
                fits &= shows if shows.any() or not against.any() else ~against
                judged = True
            if judged:
                for i in pool[fits]:
                    out.setdefault(int(i), phrase)
        return out
