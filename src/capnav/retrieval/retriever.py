"""Free-form queries over the caption-enriched object database (paper 3.4).

Order of work: read the instruction (``query.parse_instruction``); embed it (eq. 15); cosine
similarity to every caption (eq. 16); candidates of the named category first (the paper's type
filter); order them by the instruction's predicate (grid distance of eq. 17 for closest /
farthest, volume for biggest / smallest, box gap to the anchor for "next to", inferred room for
"in the kitchen") or, with none, by similarity with MMR; then verification in batches (AGENT)
until one candidate is accepted, or "not found". Every step leaves a reason in words.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from capnav.core.categories import NAMES
from capnav.core.errors import InputError
from capnav.core.grid import GridSpec
from capnav.language import context, purpose
from capnav.language.context import HALLWAY, ROOM_CUES, SceneContext, canonical_label
from capnav.language.embedder import TextEmbedder
from capnav.language.prompts import caption_name
from capnav.mapping.cmap import CapNavMap
from capnav.mapping.objects import MapObject
from capnav.retrieval.config import RetrievalConfig
from capnav.retrieval.query import BETWEEN, END_OF, ROOM_WITH, ParsedQuery, parse_instruction
from capnav.retrieval.ranking import cosine_scores, mmr, top_k
from capnav.retrieval.result import QueryResult
from capnav.retrieval.spatial import end_distance, has_long_axis, segment_distance
from capnav.retrieval.verifier import AcceptFirst, Assessment, Candidate, OfflineVerifier, Verifier, a

_VOCAB = set(NAMES)
_ROOMS = list(ROOM_CUES)
_ORDINALS = {2: "second", 3: "third", 4: "fourth", 5: "fifth"}


@dataclass
class Ranking:
    """The retrieval order with what decided it."""

    order: NDArray[np.intp]  # candidate indices, best first
    groups: NDArray[np.int64]  # per position: predicate group (ties on the predicate share one)
    mode: str  # "semantic", "predicate" or "closest"
    predicate: str | None
    weights: NDArray[np.float64]  # per object: category weight (1 named, < 1 alternative)
    terms: dict[int, dict[str, float]]  # per candidate: the predicate's values (distance, volume, ...)
    refusal: str | None = None  # a reason to answer "not found" before verification


def check_map_embeddings(objects: Sequence[MapObject], embedder: TextEmbedder) -> None:
    """Raise ``InputError`` when the map cannot be queried with ``embedder``."""
    if not objects:
        raise InputError("the map has no objects to search")
    missing = [o.id for o in objects if not o.caption or o.embedding is None]
    if len(missing) == len(objects):
        raise InputError("the map has no captions/embeddings: run `capnav caption MAP --dataset DIR` first")
    if missing:
        raise InputError(f"{len(missing)} objects have no caption or embedding (ids {missing[:10]}); "
                         "run `capnav caption` again to describe the whole map")
    models = sorted({str(o.embedding_model) for o in objects})
    if len(models) > 1:
        raise InputError(f"the map mixes embeddings of several models ({', '.join(models)}); re-run `capnav caption`")
    if models[0] != embedder.model_id:
        raise InputError(f"the map's captions were embedded with {models[0]!r} but the query embedder is "
                         f"{embedder.model_id!r}; query with the same embedder or re-run `capnav caption` "
                         "with this one")
    dims = {int(np.asarray(o.embedding).shape[-1]) for o in objects}
    if dims != {embedder.dim}:
        raise InputError(f"embedding dimension {sorted(dims)} does not match the embedder's {embedder.dim}")


class Retriever:
    def __init__(self, cmap: CapNavMap, embedder: TextEmbedder, verifier: Verifier | None = None,
                 config: RetrievalConfig | None = None) -> None:
        self.cmap = cmap
        self.embedder = embedder
        self.config = config or RetrievalConfig()
        check_map_embeddings(cmap.objects, embedder)
        self.objects = list(cmap.objects)
        self.E = np.stack([np.asarray(o.embedding, dtype=np.float32) for o in self.objects])
        occ = getattr(cmap, "occupancy", None)
        # Walls, rooms and gloss embeddings as stored at caption time (computed here for older maps).
        self.scene = SceneContext(self.objects, occ, store=cmap.caches.setdefault(context.CACHE_KEY, {}))
        purpose.use_stored_glosses(embedder, cmap.caches.get(purpose.CACHE_KEY))
        self.grid = occ.spec if occ is not None else self._grid_from_objects()
        self.cells = self.grid.to_cell(np.array([o.position[:2] for o in self.objects]))
        # An object's category: the caption's name when it is a vocabulary word, else its label.
        self.cats = []
        for o in self.objects:
            name = canonical_label(caption_name(o.caption or o.label))
            self.cats.append(name if name in _VOCAB else canonical_label(o.label))
        self.cats_arr = np.array(self.cats, dtype=object)
        self.volume = self.scene.volume
        self.verifier = verifier if verifier is not None else OfflineVerifier()
        offline = getattr(self.verifier, "fallback", None)
        if isinstance(self.verifier, OfflineVerifier):
            offline = self.verifier
        if not isinstance(offline, OfflineVerifier):
            offline = OfflineVerifier()
        offline.bind(embedder, self.scene)
        offline.use_attributes(cmap.caches.get("attributes", {}))
        #: Judges candidates for explanations, negations and landmarks whatever the verifier is.
        self.judge: OfflineVerifier = offline
        cache = cmap.caches.setdefault("verifications", {})
        if hasattr(self.verifier, "cache") and getattr(self.verifier, "cache", None) == {}:
            self.verifier.cache = cache

    def _grid_from_objects(self) -> GridSpec:
        lo = np.min([o.extent_min[:2] for o in self.objects], axis=0)
        hi = np.max([o.extent_max[:2] for o in self.objects], axis=0)
        return GridSpec.covering(float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]),
                                 self.config.grid_resolution, margin=5.0)

    # -- ordering ------------------------------------------------------------------------------
    def grid_distance(self, robot_xy: tuple[float, float]) -> NDArray[np.float64]:
        """Eq. 17: d_j = s * sqrt((r_R - r_j)^2 + (c_R - c_j)^2) in metres."""
        rc = self.grid.to_cell(np.asarray(robot_xy, dtype=np.float64))
        d = np.hypot(self.cells[:, 0] - rc[0], self.cells[:, 1] - rc[1])
        return np.asarray(d * self.grid.resolution, dtype=np.float64)

    def _of_category(self, cat: str) -> NDArray[np.intp]:
        return np.flatnonzero(self.cats_arr == cat)

    def _category_weights(self, q: ParsedQuery) -> NDArray[np.float64]:
        """Per object: 1 for the named category, the parser's weight for an alternative, else 0."""
        w = np.zeros(len(self.objects))
        for cat, weight in q.category_alternatives.items():
            w[self._of_category(canonical_label(cat))] = np.maximum(w[self._of_category(canonical_label(cat))],
                                                                     float(weight))
        if q.category is not None:
            w[self._of_category(q.category)] = 1.0
        return w

    def _excluded(self, q: ParsedQuery, pool: NDArray[np.intp], weights: NDArray[np.float64]) -> dict[int, str]:
        """Candidates of ``pool`` a negation names ("not the white one"), with the phrase.

        A negated colour is read as a definite description among the candidates: it names the
        ones that fit it best (agreement at least ``color_reject``, and at least
        ``negation_contrast`` of the best fit among the named category's candidates), not every
        candidate that is somewhat that colour; so "not the yellow lamp, the other one" excludes
        the mustard lamp although its agreement is below ``color_match``, and "not the white
        washing machine" keeps the light grey one when a white one stands beside it."""
        out: dict[int, str] = {}
        named = pool[weights[pool] >= 1.0]
        ref = named if len(named) else pool
        for phrase in q.negations:
            try:
                nq = parse_instruction(phrase)
            except InputError:
                continue
            if nq.category is not None and nq.category != q.category and not nq.colors and not nq.room:
                continue  # "not the one at the end of the table": a relation this reader does not judge
            fits = np.ones(len(pool), dtype=bool)
            judged = False
            if nq.category is not None and nq.category == q.category:
                fits &= self.cats_arr[pool] == nq.category
                judged = True
            if nq.colors:
                col = {int(i): self.judge.color(nq, self.objects[int(i)])[0] for i in pool}
                best = max((col[int(i)] for i in ref), default=0.0)
                bar = max(self.judge.config.color_reject, self.config.negation_contrast * best)
                fits &= np.array([col[int(i)] >= bar for i in pool])
                judged = True
            if nq.room is not None:
                fits &= np.array([self.scene.rooms[int(i)] == nq.room for i in pool])
                judged = True
            if nq.shapes:
                fits &= np.array([all(w.lower() in (self.objects[int(i)].caption or "").lower() for w in nq.shapes)
                                  for i in pool])
                judged = True
            if judged:
                for i in pool[fits]:
                    out.setdefault(int(i), phrase)
        return out

    def _anchors(self, q: ParsedQuery, notes: list[str], second: bool = False) -> NDArray[np.intp]:
        """The landmark's instances (the second landmark's of "between" with ``second``), resolved
        first: of its category, and when its phrase says a colour, a room or a shape, only the
        instance(s) that fit best ("the yellow lamp", "the cactus")."""
        category, phrase = (q.anchor2_category, q.anchor2_phrase) if second else (q.anchor_category, q.anchor_phrase)
        assert category is not None
        anchors = self._of_category(category)
        if len(anchors) < 2 or not phrase:
            return anchors
        try:
            aq = parse_instruction(phrase)
        except InputError:
            return anchors
        if aq.colors:
            agree = np.array([self.judge.color(aq, self.objects[k])[0] for k in anchors])
            keep = anchors[agree >= max(self.judge.config.color_reject, agree.max() - 0.05)]
            notes.append(f"landmark '{phrase}': object {', '.join(str(self.objects[k].id) for k in keep)}")
            anchors = keep
        if aq.room is not None:
            inroom = anchors[[self.scene.rooms[k] == aq.room for k in anchors]]
            anchors = inroom if len(inroom) else anchors
        if aq.shapes and len(anchors) > 1:
            # "next to the cactus": the plants whose points show the cactus's growth form.
            agree = np.array([self.judge.shape(aq, self.objects[k])[0] or 0.0 for k in anchors])
            if agree.max() > 0:
                anchors = anchors[agree >= agree.max()]
                notes.append(f"landmark '{phrase}': object {', '.join(str(self.objects[k].id) for k in anchors)}")
        return anchors

    def _order(self, q: ParsedQuery, s: NDArray[np.float32], robot_xy: tuple[float, float] | None,
               notes: list[str]) -> Ranking:
        cfg = self.config
        n = len(self.objects)
        weights = self._category_weights(q) if cfg.use_type_filter else np.zeros(n)
        named = q.category is not None or bool(q.category_alternatives)
        pool = np.flatnonzero(weights > 0)
        if named and cfg.use_type_filter and len(pool):
            tier1 = int((weights[pool] >= 1.0).sum())
            what = q.category or q.purpose or "target"
            notes.append(f"{tier1} {what}(s) in the map" + (f", {len(pool) - tier1} alternative(s) "
                                                             f"({', '.join(sorted(q.category_alternatives))})"
                                                             if len(pool) > tier1 else ""))
        else:
            if named and cfg.use_type_filter:
                notes.append(f"no object in the map is captioned or labelled {q.category or 'as one of '}"
                             + ("" if q.category else ", ".join(sorted(q.category_alternatives))))
            pool = np.arange(n)
            weights = np.ones(n)
        refusal: str | None = None
        if named and q.purpose is None and cfg.use_type_filter and len(pool) and not (weights[pool] >= 1.0).any():
            # No instance of the named category: an alternative serves only a request whose observed
            # attributes or landmark it shows ("the round wooden table" -> a round coffee table),
            # never a bare name ("the desk" is not the kitchen table). A purpose names several.
            if q.shapes:
                pool = np.array([i for i in pool if all(w.lower() in (self.objects[i].caption or "").lower()
                                                        for w in q.shapes)], dtype=np.intp)
            if not (q.colors or q.shapes or q.anchor_category) or not len(pool):
                refusal = (f"no {q.category or q.target_phrase} in the map, and nothing else fits "
                           f"'{q.target_phrase}' by what was observed")
        if q.negations and len(pool):
            neg = self._excluded(q, pool, weights)
            dropped = list(neg)
            if dropped:
                notes.append("excluded by the negation: " + ", ".join(
                    f"object {self.objects[i].id} ({neg[i]})" for i in dropped))
                had_named = bool((weights[pool] >= 1.0).any())
                pool = np.array([i for i in pool if int(i) not in neg], dtype=np.intp)
                if not len(pool) or (had_named and not (weights[pool] >= 1.0).any()):
                    # "not the white washer, the other one" presumes another of that category: an
                    # alternative category ("a fridge can serve as a washer") is no "other one".
                    refusal = (f"every {q.category or 'candidate'} matches what the instruction excludes "
                               f"({'; '.join(q.negations)})")
        group_keys: list[NDArray[np.float64]] = [-weights[pool]]
        order_keys: list[NDArray[np.float64]] = []
        predicate: str | None = None
        mode = "semantic"
        values: dict[str, NDArray[np.float64]] = {}
        if cfg.use_predicates and q.room is not None and q.room in _ROOMS and len(pool):
            rooms = [self.scene.rooms[i] for i in pool]
            in_room = np.array([r == q.room for r in rooms], dtype=np.float64)
            unknown = np.array([r is None for r in rooms], dtype=np.float64)
            strength = self.scene.room_score[pool, _ROOMS.index(q.room)]
            # Inferred room first, then objects of no inferred room, then the strength of the cues.
            group_keys.insert(0, -(2 * in_room + unknown))  # the room before the category tier
            order_keys.append(-strength)
            values["room cue"] = strength
            predicate, mode = "room", "predicate"
            notes.append(f"{int(in_room.sum())} of them appear to be in the {q.room} (inferred from nearby objects)")
            # A room is inferred, never observed: refuse only where the evidence against the named
            # room is confident, i.e. no candidate of the best category tier has a cue of it in its
            # own room (a wardrobe beside the desk of a room typed "office" by that desk says
            # "bedroom" too). Weak evidence serves the named object, not a substitute for it.
            top = weights[pool] >= weights[pool].max()
            possible = (strength >= self.scene.config.room_min_score) & top
            if not in_room.any() and not unknown.any() and not possible.any():
                where = sorted({str(r) for r in rooms})
                refusal = (f"no {q.category or q.target_phrase} stands in the {q.room}; "
                           f"{'they are' if len(pool) > 1 else 'it is'} in the {', the '.join(where)}")
            elif not in_room.any() and possible.any():
                k = int(np.argmax(strength))
                notes.append(f"none is inferred to be in the {q.room}, but object {self.objects[pool[k]].id} "
                             f"({self.scene.rooms[pool[k]]}) has {q.room} cues where it stands "
                             f"({strength[k]:.2f})")
        elif cfg.use_predicates and q.room == HALLWAY and len(pool):
            # A hallway has no characteristic objects: objects of a region without any room's cues
            # first, then the weakest cues of any room. No refusal: an untyped region is weak evidence.
            untyped = np.array([self.scene.rooms[i] is None for i in pool], dtype=np.float64)
            weakest = -self.scene.room_score[pool].max(axis=1)
            group_keys.insert(0, -untyped)
            order_keys.append(-weakest)
            values["no room cue"] = weakest
            predicate, mode = "room", "predicate"
            notes.append(f"{int(untyped.sum())} of them stand where no room's objects are (a hallway)")
        elif q.room is not None and q.room not in _ROOMS:
            notes.append(f"rooms of type '{q.room}' are not inferred from the map; the room was not used")
        if cfg.use_predicates and (q.relation is not None or q.proximity_to_anchor) and q.anchor_category is not None:
            anchors = self._anchors(q, notes)
            if len(anchors):
                gap = self.scene.gap[np.ix_(pool, anchors)]
                same = pool[:, None] == anchors[None, :]
                gap = np.where(same, np.inf, gap).min(axis=1)
                values["gap to landmark (m)"] = gap
                regions = {int(self.scene.region[k]) for k in anchors} - {-1}
                if q.relation == ROOM_WITH and regions:
                    # "the bed in the room with the pink dresser": the landmark's room region.
                    same_room = np.array([int(self.scene.region[i]) in regions for i in pool], dtype=np.float64)
                    group_keys.append(-same_room)
                    predicate = f"{ROOM_WITH} the {q.anchor_category}"
                    if not same_room.any() and refusal is None:
                        refusal = f"no {q.category or q.target_phrase} stands in the room with the {q.anchor_phrase}"
                elif q.relation == BETWEEN and q.anchor2_category is not None \
                        and len(second := self._anchors(q, notes, True)):
                    # "the table between the sofa and the armchair": distance to the segment joining
                    # the two landmarks' centres (the best pair when there are several).
                    xy = self.scene.xy
                    line = np.array([min((segment_distance(xy[i], xy[a_], xy[b_]) for a_ in anchors for b_ in second
                                          if len({int(i), int(a_), int(b_)}) == 3), default=np.inf) for i in pool])
                    values["distance to the line between the landmarks (m)"] = line
                    group_keys.append(np.round(line / 0.25))
                    predicate = f"between the {q.anchor_category} and the {q.anchor2_category}"
                elif q.relation == END_OF and len(long_ := np.array([k for k in anchors if has_long_axis(
                        self.objects[k].footprint)], dtype=np.intp)):
                    # "the chair at the end of the table": distance to the nearer end of the
                    # landmark's long axis (a round or square landmark has no end: "next to").
                    ends = np.array([min((end_distance(self.scene.xy[i], self.objects[k].footprint)
                                          for k in long_ if k != i), default=np.inf) for i in pool])
                    values["distance to the landmark's end (m)"] = ends
                    group_keys.append(np.round(ends / 0.25))
                    predicate = f"{END_OF} the {q.anchor_category}"
                elif q.proximity_to_anchor and q.proximity is not None:
                    # "the chair closest to the table": distance to the landmark, exactly.
                    centre = np.linalg.norm(self.scene.xy[pool][:, None] - self.scene.xy[anchors][None], axis=2)
                    centre = np.where(same, np.inf, centre).min(axis=1)
                    far = q.proximity == "farthest"
                    group_keys.append(-centre if far else centre)
                    predicate = f"{q.proximity} to the {q.anchor_category}"
                else:
                    group_keys.append(np.round(gap / 0.25))  # quarter-metre bins, attributes break ties
                    predicate = q.relation
                mode = "predicate"
            else:
                notes.append(f"no {q.anchor_category} in the map to be {q.relation}")
        if cfg.use_predicates and q.superlative is not None:
            vol = self.volume[pool]
            group_keys.append(-vol if q.superlative == "largest" else vol)
            values["volume (m3)"] = vol
            predicate, mode = q.superlative, "predicate"
        implicit = q.category_only and robot_xy is not None
        closest = cfg.use_attribute_heuristic and (q.proximity is not None or implicit)
        # Distance to the robot orders what no relation or superlative ordered (within the room).
        if closest and predicate in (None, "room"):
            if robot_xy is None:
                notes.append(f"'{q.proximity}' needs a robot position (--robot X,Y); ranked by similarity instead")
            else:
                d = self.grid_distance(robot_xy)[pool]
                far = q.proximity == "farthest"
                group_keys.append(-d if far else d)
                values["distance to robot (m)"] = d
                predicate, mode = ("farthest" if far else "closest"), "closest"
        sim = s[pool].astype(np.float64)
        if mode == "semantic":
            # Per category tier (named category, then alternatives), similarity with MMR.
            parts = []
            for w in sorted(set(weights[pool].tolist()), reverse=True):
                tier = pool[weights[pool] == w]
                sub = top_k(s, cfg.top_k, tier[np.lexsort((tier, -s[tier]))])
                parts.append(mmr(self.E, s, sub, cfg.mmr_lambda) if cfg.use_mmr else sub)
            order = np.concatenate(parts) if parts else pool
            tier_of = {int(i): k for k, w in enumerate(sorted(set(weights[pool].tolist()), reverse=True))
                       for i in pool[weights[pool] == w]}
            groups = np.array([tier_of[int(i)] for i in order], dtype=np.int64)
        else:
            # Lexicographic: first group key most significant; then order keys, similarity, index.
            keys = [pool.astype(np.float64), -sim, *reversed(order_keys), *reversed(group_keys)]
            perm = np.lexsort(keys)
            order = pool[perm]
            gk = np.stack([k[perm] for k in group_keys], axis=1)
            change = np.r_[True, np.any(gk[1:] != gk[:-1], axis=1)] if len(gk) else np.zeros(0, bool)
            groups = np.cumsum(change) - 1
        at = {int(i): k for k, i in enumerate(pool)}
        terms = {int(i): {name: float(v[at[int(i)]]) for name, v in values.items()} for i in pool}
        if q.ordinal and q.ordinal > 1 and mode != "semantic" and len(order):
            skip = order[: q.ordinal - 1]
            notes.append(f"'{_ORDINALS.get(q.ordinal, str(q.ordinal))}': passed over "
                         + ", ".join(f"object {self.objects[i].id}" for i in skip))
            order, groups = order[q.ordinal - 1:], groups[q.ordinal - 1:]
        return Ranking(order, groups, mode, predicate, weights, terms, refusal)

    # -- query ---------------------------------------------------------------------------------
    def query(self, instruction: str | ParsedQuery, robot_xy: tuple[float, float] | None = None) -> QueryResult:
        """Answer an instruction (text, or an already parsed ``ParsedQuery``)."""
        cfg = self.config
        if robot_xy is not None:
            xy = np.asarray(robot_xy, dtype=np.float64)
            if xy.shape != (2,) or not np.all(np.isfinite(xy)):
                raise InputError(f"robot position must be two finite numbers x, y, got {robot_xy!r}")
        q = instruction if isinstance(instruction, ParsedQuery) else parse_instruction(instruction, self.embedder)
        t0 = time.perf_counter()
        e_q = self.embedder.embed([q.text])[0]
        t1 = time.perf_counter()
        s = cosine_scores(self.E, e_q)
        notes: list[str] = []
        rk = self._order(q, s, robot_xy, notes)
        order, mode, predicate = rk.order, rk.mode, rk.predicate
        t2 = time.perf_counter()
        chosen_i: int | None = None
        verdict_reason = ""
        verifier = self.verifier if cfg.use_verifier else AcceptFirst()
        judged: dict[int, Assessment] = {}
        limit = cfg.batch_size * cfg.max_batches
        if rk.refusal is not None:
            verdict_reason = rk.refusal
        elif q.category is not None and cfg.use_type_filter and not len(self._of_category(q.category)) \
                and not q.category_alternatives and isinstance(verifier, AcceptFirst):
            verdict_reason = f"no {q.category} in the map"
        else:
            cands = order[:limit] if mode != "semantic" else order
            for b in range(0, min(len(cands), limit), cfg.batch_size):
                idx = cands[b:b + cfg.batch_size]
                batch = [Candidate(self.objects[i], float(s[i]), b + k, int(rk.groups[b + k]),
                                   float(rk.weights[i])) for k, i in enumerate(idx)]
                for k, c in enumerate(batch):
                    judged[int(idx[k])] = self.judge.assess(q, c, k / max(len(batch), 1))
                v = verifier.verify(q, batch)
                verdict_reason = v.reason
                if v.index is not None:
                    chosen_i = int(idx[v.index])
                    break
            if chosen_i is not None and isinstance(verifier, AcceptFirst) and mode == "semantic" \
                    and s[chosen_i] < cfg.min_score:
                verdict_reason = f"best similarity {s[chosen_i]:.2f} is below the threshold {cfg.min_score:.2f}"
                chosen_i = None
        t3 = time.perf_counter()
        timings = {"embed": t1 - t0, "rank": t2 - t1, "verify": t3 - t2}
        runners = self._runners_up(rk, s, judged, chosen_i)
        dist = None
        if robot_xy is not None and chosen_i is not None:
            dist = float(self.grid_distance(robot_xy)[chosen_i])
        reason = self._explain(q, chosen_i, s, rk, notes, verdict_reason, dist, verifier, runners, judged)
        return QueryResult(q.text, self.objects[chosen_i] if chosen_i is not None else None, chosen_i is not None,
                           float(s[chosen_i]) if chosen_i is not None else 0.0,
                           [(self.objects[i], sc) for i, sc, _, _ in runners], predicate, reason, timings,
                           mode, dist, q.to_dict(), [{"terms": t, "why": w} for _, _, t, w in runners],
                           judged[chosen_i].terms if chosen_i in judged else {})

    def _final(self, rk: Ranking, judged: dict[int, Assessment]) -> list[int]:
        """Every ranked candidate in the order the decision considered them: by predicate group,
        then (accepted first) by the verifier's value; unjudged ones after, in retrieval order."""
        pos = {int(i): k for k, i in enumerate(rk.order)}
        group = {int(i): int(g) for i, g in zip(rk.order, rk.groups, strict=True)}

        def key(i: int) -> tuple[int, int, float, int]:
            a_ = judged.get(i)
            if a_ is None:
                return (1, group[i], 0.0, pos[i])
            return (0 if a_.ok else 1, group[i], -a_.value, pos[i])

        return sorted((int(i) for i in rk.order), key=key)

    def _runners_up(self, rk: Ranking, s: NDArray[np.float32], judged: dict[int, Assessment],
                    chosen: int | None) -> list[tuple[int, float, dict[str, float], str]]:
        """(index, final score, terms, why it lost) of the next candidates, in decision order.
        The final score is the verifier's value when it judged the candidate, else similarity."""
        out = []
        best = judged.get(chosen) if chosen is not None else None
        for i in self._final(rk, judged):
            if i == chosen:
                continue
            a_ = judged.get(i)
            terms = dict(a_.terms) if a_ is not None else {"similarity": round(float(s[i]), 3)}
            terms.update({k: round(v, 3) for k, v in rk.terms.get(i, {}).items()})
            if a_ is not None and not a_.ok:
                why = f"rejected: {a_.reason}"
            elif a_ is None:
                why = "not verified (a candidate before it was accepted)" if chosen is not None else "not verified"
            else:
                why = self._difference(a_, best, rk, i, chosen)
            score = a_.value if a_ is not None else float(s[i])
            out.append((i, float(score), terms, why))
            if len(out) >= self.config.runners_up:
                break
        return out

    def _difference(self, a_: Assessment, best: Assessment | None, rk: Ranking, i: int, chosen: int | None) -> str:
        """The terms in which the chosen candidate beat this one."""
        if best is None or chosen is None:
            return f"acceptable (score {a_.value:.2f})"
        group = {int(k): int(g) for k, g in zip(rk.order, rk.groups, strict=True)}
        if group.get(i, 0) > group.get(chosen, 0):
            pred = rk.terms.get(i, {})
            mine = rk.terms.get(chosen, {})
            diffs = [f"{k} {pred[k]:.2f} vs {mine[k]:.2f}" for k in pred if k in mine and abs(pred[k] - mine[k]) > 1e-6]
            return f"ranked after it by {rk.predicate or 'category'}" + (f" ({'; '.join(diffs)})" if diffs else "")
        diffs = [f"{k} {a_.terms[k]:.2f} vs {best.terms[k]:.2f}" for k in a_.terms
                 if k in best.terms and k != "similarity" and a_.terms[k] < best.terms[k] - 1e-6]
        return f"lower score {a_.value:.2f} vs {best.value:.2f}" + (f" ({'; '.join(diffs)})" if diffs else "")

    def _explain(self, q: ParsedQuery, i: int | None, s: NDArray[np.float32], rk: Ranking, notes: list[str],
                 verdict: str, dist: float | None, verifier: Verifier,
                 runners: list[tuple[int, float, dict[str, float], str]], judged: dict[int, Assessment]) -> str:
        target = q.target_phrase or q.text
        if i is None:
            base = f"Not found: nothing in the map is {a(target)}"
            text = f"{base} ({verdict})."
            if runners:
                text += " Closest candidates: " + "; ".join(
                    f"object {self.objects[k].id} ({self.cats[k]}, score {sc:.2f}) {why}"
                    for k, sc, _, why in runners[:3]) + "."
            return text + (f" {'; '.join(notes)}." if notes else "")
        o = self.objects[i]
        mode, predicate = rk.mode, rk.predicate
        if mode == "closest":
            how = f"it is the {predicate} {q.category or target} to the robot" \
                  + (f" ({dist:.1f} m in the grid)" if dist is not None else "")
        elif mode == "predicate":
            how = f"it best satisfies '{predicate}'"
        elif i in judged and judged[i].ok:
            how = f"it has the highest verification score ({judged[i].value:.2f})"
        else:
            how = "it is the first candidate in the similarity ranking"
        text = f"Chose object {o.id} ({o.caption}) because {how}; caption similarity {s[i]:.2f}"
        if verdict:
            text += f"; verifier ({verifier.name}): {verdict}"
        if notes:
            text += f". Notes: {'; '.join(notes)}"
        return text + "."
