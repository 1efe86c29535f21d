"""``describe_map``: views -> captions -> embeddings for every object of a map (paper 3.3).

Captions are cached in ``cmap.caches["captions"]`` under the captioner's ``cache_key`` (a hash of
the views' content, the prompt and the model), so a rerun is free and reproducible; the cache
travels inside the map file, as the paper released its cached captions. The measured colours,
shape words and surface go to ``cmap.caches["attributes"]`` so that verification does not
recompute them per query.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

from capnav.core.progress import track
from capnav.language import context, purpose
from capnav.language.captioner import Captioner
from capnav.language.context import ContextConfig, SceneContext
from capnav.language.embedder import TextEmbedder
from capnav.language.offline_captioner import ObservationCaptioner
from capnav.language.views import FrameReader, ViewConfig, select_views_all
from capnav.mapping.cmap import CapNavMap


@dataclass
class DescribeReport:
    objects: int = 0
    views_selected: int = 0
    captions_new: int = 0
    captions_cached: int = 0
    embeddings_new: int = 0
    fallbacks: list[tuple[int, str]] = field(default_factory=list)
    seconds: dict[str, float] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"objects": self.objects, "views_selected": self.views_selected, "captions_new": self.captions_new,
                "captions_cached": self.captions_cached,
                "embeddings_new": self.embeddings_new, "fallbacks": [list(f) for f in self.fallbacks],
                "seconds": self.seconds}


def describe_map(cmap: CapNavMap, reader: FrameReader | None, captioner: Captioner, embedder: TextEmbedder,
                 progress: bool = True, view_config: ViewConfig | None = None,
                 context_config: ContextConfig | None = None, reselect_views: bool = False) -> DescribeReport:
    """Fill ``views``, ``caption``, ``caption_source``, ``embedding`` and ``embedding_model`` of
    every object in place. Views are (re)selected from ``reader`` for objects without views (or
    all objects with ``reselect_views``); with ``reader=None`` existing views are kept."""
    rep = DescribeReport(objects=len(cmap.objects))
    t0 = time.perf_counter()
    if reader is not None:
        todo = [o for o in cmap.objects if reselect_views or not o.views]
        if todo:
            chosen = select_views_all(todo, reader, view_config, progress=progress)
            for o in todo:
                o.views = chosen.get(o.id, [])
            rep.views_selected = len(todo)
    t1 = time.perf_counter()
    scene = SceneContext(cmap.objects, cmap.occupancy, context_config or ContextConfig(),
                         store=cmap.caches.setdefault(context.CACHE_KEY, {}))
    cache = cmap.caches.setdefault("captions", {})
    before = {o.id: o.caption for o in cmap.objects}
    for obj in track(cmap.objects, f"captioning ({captioner.model_id})", enabled=progress):
        key = captioner.cache_key(obj, scene)
        hit = cache.get(key)
        if hit is not None:
            obj.caption, obj.caption_source = hit["caption"], hit["source"]
            rep.captions_cached += 1
            continue
        cap = captioner.caption(obj, scene)
        obj.caption, obj.caption_source = cap.text, cap.source
        rep.captions_new += 1
        if cap.source.startswith("fallback"):
            rep.fallbacks.append((obj.id, cap.source))
        else:
            # Fallbacks are not cached: the next run should try the model again.
            cache[key] = {"caption": cap.text, "source": cap.source, "object": obj.id}
    attrs = cmap.caches.setdefault("attributes", {})
    namer = ObservationCaptioner()
    for obj in cmap.objects:
        attrs[str(obj.id)] = {key: [[c.name, *[round(v, 3) for v in c.lab], round(c.fraction, 4),
                                     round(c.distance, 3)] for c in cols]
                              for key, cols in (("colors", namer.colors(obj)), ("base_colors", namer.base_colors(obj)))}
        attrs[str(obj.id)]["shapes"] = namer.shapes(obj)
        attrs[str(obj.id)]["surface"] = namer.surface(obj).to_list()
    t2 = time.perf_counter()
    # Only captions that changed are embedded again (after a map update: moved and new objects).
    todo_emb = [o for o in cmap.objects if o.embedding is None or o.embedding_model != embedder.model_id
                or o.caption != before[o.id]]
    if todo_emb:
        vecs = embedder.embed([o.caption or "" for o in todo_emb])
        for o, v in zip(todo_emb, vecs, strict=True):
            o.embedding = v.copy()
            o.embedding_model = embedder.model_id
    rep.embeddings_new = len(todo_emb)
    # Requests by purpose compare to every category's glosses: embedded once here, not per query.
    cmap.caches[purpose.CACHE_KEY] = purpose.gloss_index(embedder).to_store()
    t3 = time.perf_counter()
    rep.seconds = {"views": t1 - t0, "captions": t2 - t1, "embeddings": t3 - t2}
    cmap.meta["language"] = {"captioner": captioner.model_id, "embedder": embedder.model_id,
                             "embedding_dim": embedder.dim}
    return rep
