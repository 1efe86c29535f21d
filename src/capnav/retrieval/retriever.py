"""Free-form queries over the caption-enriched object database (paper 3.4).

Order of work: read the instruction (``query.parse_instruction``); embed it (eq. 15); cosine
similarity to every caption (eq. 16); candidates of the named category first (the paper's type
filter); order them by the instruction's predicate (grid distance of eq. 17 for closest /
farthest, volume for biggest / smallest, box gap to the anchor for "next to", inferred room for
"in the kitchen") or, with none, by similarity with MMR; then verification in batches (AGENT)
until one candidate is accepted, or "not found". Every step leaves a reason in words.
"""

from __future__ import annotations

import copy
import re
import time
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from capnav.core.categories import NAMES
from capnav.core.errors import InputError
from capnav.core.grid import GridSpec
from capnav.language import context, purpose
from capnav.language.context import SceneContext, canonical_label
from capnav.language.embedder import TextEmbedder
from capnav.language.prompts import caption_name
from capnav.mapping.cmap import CapNavMap
from capnav.mapping.objects import MapObject
from capnav.retrieval import constraints
from capnav.retrieval import time as time_scope
from capnav.retrieval.config import RetrievalConfig
from capnav.retrieval.query import ParsedQuery, parse_goals, parse_instruction
from capnav.retrieval.ranking import Ranking, cosine_scores
from capnav.retrieval.result import QueryResult
from capnav.retrieval.spatial import FloorDistances
from capnav.retrieval.verifier import AcceptFirst, Assessment, Candidate, OfflineVerifier, Verifier, a

_VOCAB = set(NAMES)
#: Instructions whose reading a retriever keeps (``Retriever.read_goals``).
READINGS = 1024


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
                 config: RetrievalConfig | None = None, time_aware: bool = True) -> None:
        self.cmap = cmap
        # A map of several recordings answers about time (retrieval/time.py); its scoped retrievers do not.
        self._time = time_aware and time_scope.has_time(cmap)
        self._scoped: dict[str, Retriever] = {}
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
        self._floor: FloorDistances | None = None  # walking distances, built on the first "closest"
        #: Bytes of walk fields the walking distances keep (None: ``spatial.FIELD_BYTES``; 0: none).
        self.field_bytes: int | None = None
        self._readings: OrderedDict[str, list[ParsedQuery]] = OrderedDict()
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

    def robot_distance(self, robot_xy: tuple[float, float], among: NDArray[np.intp] | None = None
                       ) -> tuple[NDArray[np.float64], str]:
        """Distances from the robot to every object and what they measure: along the floor
        (``RetrievalConfig.distance == "walking"``, when the map has a grid and the robot stands
        where a walk starts) else eq. 17's straight grid distance. With ``among`` (object indices)
        only those are sure to be measured: a walk stops once they are (the others may be nan).
        Whether it is a walk does not depend on ``among``: a walk that stopped early reached one of
        them, and one that reached none of them ran to the end and measured every object."""
        floor = self.floor_distances()
        if floor is not None:
            d = floor.from_point(robot_xy, among)
            if np.isfinite(d).any():
                return np.where(np.isfinite(d), d, self.grid_distance(robot_xy) + 1e6), "walking"
        return self.grid_distance(robot_xy), "straight"

    def floor_distances(self) -> FloorDistances | None:
        """The walking distances of this map (None with ``distance="straight"`` or no occupancy)."""
        occ = getattr(self.cmap, "occupancy", None)
        if self.config.distance != "walking" or occ is None:
            return None
        if self._floor is None:
            los = np.array([o.extent_min[:2] for o in self.objects], dtype=np.float64)
            his = np.array([o.extent_max[:2] for o in self.objects], dtype=np.float64)
            self._floor = FloorDistances(occ, los, his, field_bytes=self.field_bytes)
        return self._floor

    def read_goals(self, instruction: str) -> list[ParsedQuery]:
        """``query.parse_goals`` with this retriever's embedder, kept for the ``READINGS`` most
        recently read instructions (a reading depends on the words and the embedder only; a server
        hears the same requests again): each call gets its own copy to change."""
        hit = self._readings.pop(instruction, None)
        if hit is None:
            hit = parse_goals(instruction, self.embedder)
            while len(self._readings) >= READINGS:
                self._readings.popitem(last=False)
        self._readings[instruction] = hit
        return copy.deepcopy(hit)

    def of_category(self, cat: str) -> NDArray[np.intp]:
        """Indices of the objects of category ``cat``."""
        return np.flatnonzero(self.cats_arr == cat)

    def _order(self, q: ParsedQuery, s: NDArray[np.float32], robot_xy: tuple[float, float] | None,
               notes: list[str]) -> Ranking:
        """The candidates in retrieval order: every constraint of ``q`` narrows or keys them."""
        return constraints.rank(self, q, s, robot_xy, notes)[0]

    # -- query ---------------------------------------------------------------------------------
    def query(self, instruction: str | ParsedQuery, robot_xy: tuple[float, float] | None = None) -> QueryResult:
        """Answer an instruction (text, or an already parsed ``ParsedQuery``)."""
        cfg = self.config
        if robot_xy is not None:
            xy = np.asarray(robot_xy, dtype=np.float64)
            if xy.shape != (2,) or not np.all(np.isfinite(xy)):
                raise InputError(f"robot position must be two finite numbers x, y, got {robot_xy!r}")
        if self._time and isinstance(instruction, str):
            answered = self._about_time(instruction, robot_xy)
            if isinstance(answered, QueryResult):
                return answered
            instruction = answered or instruction
        q = instruction if isinstance(instruction, ParsedQuery) else parse_instruction(instruction, self.embedder)
        t0 = time.perf_counter()
        e_q = self.embedder.embed([q.text])[0]
        t1 = time.perf_counter()
        s = cosine_scores(self.E, e_q)
        notes: list[str] = list(q.notes)  # what the reading of the instruction could not use
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
        elif q.category is not None and cfg.use_type_filter and not len(self.of_category(q.category)) \
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
        miss_i = self._out_of_reach(rk, chosen_i)
        if miss_i is not None:  # every candidate stands beyond the relation's reach: not what was asked
            chosen_i = None
            what = q.category or q.target_phrase or "such object"
            verdict_reason = (f"no {what} stands {q.relation} {a(q.anchor_category or 'landmark')}: the nearest is "
                              f"{min(rk.out_of_reach.values()):.1f} m away (within {rk.reach:.1f} m)")
        t3 = time.perf_counter()
        timings = {"embed": t1 - t0, "rank": t2 - t1, "verify": t3 - t2}
        runners = self._runners_up(rk, s, judged, chosen_i)
        dist, dist_kind = None, "straight"
        if robot_xy is not None and chosen_i is not None:
            # Measured as the ranking measured it: a walk (cached by the distance constraint) when
            # the answer was ranked by distance, else eq. 17's straight grid distance, so that a
            # sentence's distance never costs a search over the whole floor.
            d, dist_kind = self.robot_distance(robot_xy, np.array([chosen_i])) if mode == "closest" \
                else (self.grid_distance(robot_xy), "straight")
            dist = float(d[chosen_i])
        reason = self._explain(q, chosen_i, s, rk, notes, verdict_reason, dist, verifier, runners, judged,
                               dist_kind)
        said_of = chosen_i if miss_i is None else miss_i
        unmet = rk.unmet.get(said_of) if said_of is not None else None
        if unmet is not None and miss_i is None:  # within the word's reach, farther than "next to": said
            reason += f" It does not meet the request's relation: {unmet}."
        elif miss_i is not None:  # refused; the best candidate is kept aside (a search looks on from it)
            o = self.objects[miss_i]
            reason = f"Not found: {verdict_reason}. The best candidate, object {o.id} ({o.caption or o.label}): " \
                     f"{unmet}."
        return QueryResult(q.text, self.objects[chosen_i] if chosen_i is not None else None, chosen_i is not None,
                           float(s[chosen_i]) if chosen_i is not None else 0.0,
                           [(self.objects[i], sc) for i, sc, _, _ in runners], predicate, reason, timings,
                           mode, dist, q.to_dict(),
                           [{"terms": t, "why": w, "similarity": float(s[i]),
                             "verifier": judged[i].value if i in judged else None} for i, _, t, w in runners],
                           judged[chosen_i].terms if chosen_i in judged else {},
                           judged[chosen_i].value if chosen_i in judged else None, unmet,
                           self.objects[miss_i] if miss_i is not None else None)

    @staticmethod
    def _out_of_reach(rk: Ranking, chosen_i: int | None) -> int | None:
        """The verifier's choice when every candidate stands beyond the request's relation of
        nearness (its reach: "the easy chair beside the settee" with the only armchair 1.5 m from any
        sofa), so the query refuses; None when one of them stands within it (or no relation)."""
        if chosen_i is None or rk.reach is None or not len(rk.order):
            return None
        return chosen_i if all(int(i) in rk.out_of_reach for i in rk.order) else None

    def _about_time(self, instruction: str, robot_xy: tuple[float, float] | None
                    ) -> QueryResult | ParsedQuery | None:
        """Time words narrow the objects; a best match that is retired is "not found" (when last seen).
        Otherwise the present objects answer (None, or the request already parsed).

        Without time words the whole history is asked only when the request says more than a kind
        (a colour, a room, a neighbour, a superlative ...) or no object of that kind is left: "the
        writing desk" is any desk there is now, however near the robot a desk that is gone once
        stood, while "the pink chair" is the pink one even when another chair remains. A request
        about the robot ("the nearest chair") is about now. The history is ranked without the
        robot's position: nearness to a place an object has left says nothing about which one was
        meant."""
        scope = time_scope.read_time(instruction)
        if scope is None and not self.cmap.retired:
            return None
        parsed: ParsedQuery | None = None
        if scope is None:
            parsed = parse_instruction(instruction, self.embedder)
            bare = not (parsed.has_attributes or parsed.negations or parsed.ordinal)
            if parsed.proximity is not None or (bare and parsed.category is not None
                                                and len(self.of_category(parsed.category))):
                return parsed
        key = scope.kind if scope is not None else "all"
        if key not in self._scoped:
            sub_map, _ = time_scope.scoped_map(self.cmap, scope)
            if not sub_map.objects:
                why = {"moved": "no object has moved between the recordings",
                       "new": "no object is new in the latest recording"}.get(key, "the map has no objects")
                return QueryResult(instruction, None, False, 0.0, [], None, why)
            self._scoped[key] = Retriever(sub_map, self.embedder, self.verifier, self.config, time_aware=False)
        sub = self._scoped[key]
        if scope is not None and scope.kind in ("moved", "new"):
            listed = self._list_changed(sub, scope, robot_xy)
            if listed is not None:
                return listed
        if parsed is not None:
            res = sub.query(parsed, None)
        else:
            assert scope is not None
            res = sub.query(scope.text, robot_xy)
        gone = {o.id for o in self.cmap.retired}
        if res.chosen is not None and res.chosen.id in gone:
            return replace(res, chosen=None, found=False, score=0.0, distance_m=None, terms={},
                           reason=time_scope.gone_reason(res.chosen, self.cmap))
        if scope is None:
            return parsed
        if res.chosen is not None:
            res = replace(res, reason=f"{res.reason}; {time_scope.when_seen(res.chosen, self.cmap)}")
        return res

    @staticmethod
    def _list_changed(sub: Retriever, scope: time_scope.TimeScope, robot_xy: tuple[float, float] | None
                      ) -> QueryResult | None:
        """"What is new (in the kitchen)": no object named, so every changed object (in that room)
        answers; the nearest to the robot (else the lowest id) is the goal. None when one is named."""
        words = re.findall(r"[a-z]+", scope.text.lower())
        rooms = {r for r in sub.scene.rooms if r}
        room = next((r for r in rooms if re.search(rf"\b{re.escape(r)}\b", scope.text.lower())), None)
        rest = [w for w in words if w not in {"something", "anything", "thing", "things", "in", "the", "a", "an", "on",
                                              "at", "near", "by", "object", "objects"}
                and not (room and w in room.split())]
        if rest:
            return None
        idx = [i for i, o in enumerate(sub.objects) if room is None or sub.scene.rooms[i] == room]
        if not idx:
            return QueryResult(scope.text, None, False, 0.0, [], "room", f"nothing {scope.kind} in the {room}")
        if robot_xy is not None:
            d = sub.grid_distance(robot_xy)
            idx.sort(key=lambda i: (float(d[i]), sub.objects[i].id))
        best = sub.objects[idx[0]]
        what = ", ".join(f"{sub.objects[i].label} {sub.objects[i].id}" for i in idx)
        where = f" in the {room}" if room else ""
        reason = f"{scope.kind}{where}: {what}; the goal is the {best.label} {best.id}" + (
            " (nearest)" if robot_xy is not None and len(idx) > 1 else "")
        return QueryResult(scope.text, best, True, 1.0, [(sub.objects[i], 1.0) for i in idx[1:]],
                           "room" if room else None, reason, mode="history")

    def _final(self, rk: Ranking, judged: dict[int, Assessment]) -> list[int]:
        """Every ranked candidate in the order the decision considered them: by predicate group,
        then (accepted first) by the verifier's value; unjudged ones after, in retrieval order."""
        pos = {int(i): k for k, i in enumerate(rk.order)}
        group = {int(i): int(g) for i, g in zip(rk.order, rk.groups, strict=True)}

        def key(i: int) -> tuple[int, int, int, float, int]:
            a_ = judged.get(i)
            if a_ is None:
                return (1, group[i], 0, 0.0, pos[i])
            return (0 if a_.ok else 1, group[i], -constraints.shown_count(a_.evidence), -a_.value, pos[i])

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
                why = "not verified (one before it was accepted)" if chosen is not None else "not verified"
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
            return f"acceptable (verification score {a_.value:.2f})"
        group = {int(k): int(g) for k, g in zip(rk.order, rk.groups, strict=True)}
        if group.get(i, 0) > group.get(chosen, 0):
            pred = rk.terms.get(i, {})
            mine = rk.terms.get(chosen, {})
            diffs = [f"{k} {pred[k]:.2f} vs {mine[k]:.2f}" for k in pred if k in mine and abs(pred[k] - mine[k]) > 1e-6]
            by = f"by '{rk.predicate}'" if rk.predicate else "as a stand-in category"
            return f"ranked after the chosen object {by}" + (f" ({'; '.join(diffs)})" if diffs else "")
        diffs = [f"{k} {a_.terms[k]:.2f} vs {best.terms[k]:.2f}" for k in a_.terms
                 if k in best.terms and k != "similarity" and a_.terms[k] < best.terms[k] - 1e-6]
        if constraints.shown_count(a_.evidence) < constraints.shown_count(best.evidence):
            shown = "/".join(constraints.shown_kinds(best.evidence))
            return (f"the map shows the chosen object's {shown}, not this one's"
                    + (f" ({'; '.join(diffs)})" if diffs else ""))
        return (f"lower verification score {a_.value:.2f} vs {best.value:.2f}"
                + (f" ({'; '.join(diffs)})" if diffs else ""))

    def _explain(self, q: ParsedQuery, i: int | None, s: NDArray[np.float32], rk: Ranking, notes: list[str],
                 verdict: str, dist: float | None, verifier: Verifier,
                 runners: list[tuple[int, float, dict[str, float], str]], judged: dict[int, Assessment],
                 dist_kind: str = "straight") -> str:
        target = q.target_phrase or q.text
        extra = f" Notes: {'; '.join(n.rstrip('.') for n in notes)}." if notes else ""
        if i is None:
            # The verifier's clause speaks of one candidate ("it is a plant, not a cabinet"): name it.
            who = next((k for k, a_ in judged.items() if not a_.ok and a_.reason == verdict), None)
            if who is not None:
                why = (f"the best candidate, object {self.objects[who].id} ({self.cats[who]}), was rejected by the "
                       f"{verifier.name} verifier: {verdict}")
            else:
                why = verdict
            text = f"Not found: nothing in the map is {a(target)}" + (f"; {why}." if why else ".")
            rest = [(k, w) for k, _, _, w in runners if k != who][:3]
            if rest:
                text += " Other candidates: " + "; ".join(
                    f"object {self.objects[k].id} ({self.cats[k]}) {w.replace('rejected: ', 'was rejected: ', 1)}"
                    for k, w in rest) + "."
            return text + extra
        o = self.objects[i]
        mode, predicate = rk.mode, rk.predicate
        if mode == "closest":
            how = f"it is the {predicate} {q.category or target} to the robot" \
                  + ("" if dist is None else f" ({dist:.1f} m walking along the floor)"
                     if dist_kind == "walking" else f" ({dist:.1f} m in a straight line on the grid)")
        elif mode == "predicate":
            how = f"it best satisfies '{f'in the {q.room}' if predicate == 'room' and q.room else predicate}'"
        elif i in judged and judged[i].ok:
            how = f"it has the highest verification score ({judged[i].value:.2f})"
        else:
            how = "it is the first candidate in the similarity ranking"
        caption = o.caption or o.label  # whole: callers find the caption in the reason
        text = f"Chose object {o.id} ({caption}) because {how}; caption similarity {s[i]:.2f}."
        if verdict:
            text += f" The {verifier.name} verifier accepted it: {verdict}."
        return text + extra
