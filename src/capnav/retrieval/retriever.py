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

import numpy as np
from numpy.typing import NDArray

from capnav.core.categories import NAMES
from capnav.core.errors import InputError
from capnav.core.grid import GridSpec
from capnav.language.context import ROOM_CUES, SceneContext, canonical_label
from capnav.language.embedder import TextEmbedder
from capnav.language.prompts import caption_name
from capnav.mapping.cmap import CapNavMap
from capnav.mapping.objects import MapObject
from capnav.retrieval.config import RetrievalConfig
from capnav.retrieval.query import ParsedQuery, parse_instruction
from capnav.retrieval.ranking import cosine_scores, mmr, top_k
from capnav.retrieval.result import QueryResult
from capnav.retrieval.verifier import AcceptFirst, Candidate, OfflineVerifier, Verifier, a

_VOCAB = set(NAMES)
_ROOMS = list(ROOM_CUES)


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
        self.scene = SceneContext(self.objects, occ)
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
        if isinstance(offline, OfflineVerifier):
            offline.bind(embedder, self.scene)
            offline.use_attributes(cmap.caches.get("attributes", {}))
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

    def _order(self, q: ParsedQuery, s: NDArray[np.float32], robot_xy: tuple[float, float] | None,
               notes: list[str]) -> tuple[NDArray[np.intp], str, str | None]:
        cfg = self.config
        pool = np.arange(len(self.objects))
        if q.category is not None and cfg.use_type_filter:
            typed = self._of_category(q.category)
            if len(typed):
                pool = typed
                notes.append(f"{len(typed)} {q.category}(s) in the map")
            else:
                notes.append(f"no object in the map is captioned or labelled {q.category}")
        keys: list[NDArray[np.float64]] = []
        predicate: str | None = None
        mode = "semantic"
        if cfg.use_predicates and q.room is not None:
            in_room = np.array([self.scene.rooms[i] == q.room for i in pool], dtype=np.float64)
            # Inferred room first, then the strength of that room's cues (when none qualifies).
            strength = self.scene.room_score[pool, _ROOMS.index(q.room)]
            keys.append(-(in_room + np.round(strength, 2)))
            predicate, mode = "room", "predicate"
            notes.append(f"{int(in_room.sum())} of them appear to be in the {q.room} (inferred from nearby objects)")
        if cfg.use_predicates and q.relation is not None and q.anchor_category is not None:
            anchors = self._of_category(q.anchor_category)
            if len(anchors):
                gap = self.scene.gap[np.ix_(pool, anchors)]
                same = pool[:, None] == anchors[None, :]
                gap = np.where(same, np.inf, gap).min(axis=1)
                keys.append(np.round(gap / 0.25))  # quarter-metre bins, similarity breaks ties
                predicate, mode = q.relation, "predicate"
            else:
                notes.append(f"no {q.anchor_category} in the map to be {q.relation}")
        if cfg.use_predicates and q.superlative is not None:
            vol = self.volume[pool]
            keys.append(-vol if q.superlative == "largest" else vol)
            predicate, mode = q.superlative, "predicate"
        implicit = q.category_only and robot_xy is not None
        closest = cfg.use_attribute_heuristic and (q.proximity is not None or implicit)
        if closest and not keys:
            if robot_xy is None:
                notes.append(f"'{q.proximity}' needs a robot position (--robot X,Y); ranked by similarity instead")
            else:
                d = self.grid_distance(robot_xy)[pool]
                far = q.proximity == "farthest"
                keys.append(-d if far else d)
                predicate, mode = ("farthest" if far else "closest"), "closest"
        if not keys:
            order = pool[np.lexsort((pool, -s[pool]))]
            order = top_k(s, cfg.top_k, order)
            if cfg.use_mmr:
                order = mmr(self.E, s, order, cfg.mmr_lambda)
            return order, mode, predicate
        # Lexicographic: first key most significant; similarity then index break ties.
        sort_keys: list[NDArray[np.float64]] = [pool.astype(np.float64), -s[pool].astype(np.float64)]
        sort_keys += list(reversed(keys))
        order = pool[np.lexsort(sort_keys)]
        return order, mode, predicate

    # -- query ---------------------------------------------------------------------------------
    def query(self, instruction: str, robot_xy: tuple[float, float] | None = None) -> QueryResult:
        cfg = self.config
        if robot_xy is not None:
            xy = np.asarray(robot_xy, dtype=np.float64)
            if xy.shape != (2,) or not np.all(np.isfinite(xy)):
                raise InputError(f"robot position must be two finite numbers x, y, got {robot_xy!r}")
        q = parse_instruction(instruction)
        t0 = time.perf_counter()
        e_q = self.embedder.embed([q.text])[0]
        t1 = time.perf_counter()
        s = cosine_scores(self.E, e_q)
        notes: list[str] = []
        order, mode, predicate = self._order(q, s, robot_xy, notes)
        t2 = time.perf_counter()
        chosen_i: int | None = None
        verdict_reason = ""
        verifier = self.verifier if cfg.use_verifier else AcceptFirst()
        if q.category is not None and cfg.use_type_filter and not len(self._of_category(q.category)) \
                and isinstance(verifier, AcceptFirst):
            verdict_reason = f"no {q.category} in the map"
        else:
            cands = order[: cfg.batch_size * cfg.max_batches] if mode != "semantic" else order
            for b in range(0, min(len(cands), cfg.batch_size * cfg.max_batches), cfg.batch_size):
                idx = cands[b:b + cfg.batch_size]
                batch = [Candidate(self.objects[i], float(s[i]), b + k) for k, i in enumerate(idx)]
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
        runners = [(self.objects[i], float(s[i])) for i in order[: cfg.runners_up + 1] if i != chosen_i]
        runners = runners[: cfg.runners_up]
        dist = None
        if robot_xy is not None and chosen_i is not None:
            dist = float(self.grid_distance(robot_xy)[chosen_i])
        reason = self._explain(q, chosen_i, s, mode, predicate, notes, verdict_reason, dist, verifier)
        return QueryResult(q.text, self.objects[chosen_i] if chosen_i is not None else None, chosen_i is not None,
                           float(s[chosen_i]) if chosen_i is not None else 0.0, runners, predicate, reason, timings,
                           mode, dist, q.to_dict())

    def _explain(self, q: ParsedQuery, i: int | None, s: NDArray[np.float32], mode: str, predicate: str | None,
                 notes: list[str], verdict: str, dist: float | None, verifier: Verifier) -> str:
        target = q.target_phrase or q.text
        if i is None:
            base = f"Not found: nothing in the map is {a(target)}"
            return f"{base} ({verdict})." + (f" {'; '.join(notes)}." if notes else "")
        o = self.objects[i]
        how = {"closest": f"it is the {predicate} {q.category or target} to the robot"
                          + (f" ({dist:.1f} m in the grid)" if dist is not None else ""),
               "predicate": f"it best satisfies '{predicate}'", "semantic": "its caption is the most similar"}[mode]
        text = f"Chose object {o.id} ({o.caption}) because {how}; caption similarity {s[i]:.2f}"
        if verdict:
            text += f"; verifier ({verifier.name}): {verdict}"
        if notes:
            text += f". Notes: {'; '.join(notes)}"
        return text + "."

