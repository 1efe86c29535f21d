"""Where an object would be: the map's rooms ranked for a category, as places to look from.

A search for a chair that is not where the map says should look first where chairs stand. The
map's free space is cut into room regions (``language.rooms.segment_rooms``, the regions captions
use); each region is weighed by two cues read from the map alone:

* its room type: P(category | room type) from ``language.room_prior.ROOM_PRIOR`` (the public scene
  statistics the room captions use), averaged over the region's room-type posterior given what
  stands in it; a category that table does not know (or a region without room cues) is neutral;
* its neighbours: how close, in the text embedder's space, the region's objects' labels are to
  the category (a stool is looked for beside tables and counters): the mean of the three closest,
  measured above the median similarity of all the map's labels (an embedder finds any two
  furniture words somewhat alike; only the excess says "usual neighbour").

Each region gives standing points on its open floor (the cell farthest from walls, then more
points at least ``spacing`` apart in a large region), from which a look around sees the room.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from capnav.core.grid import FREE
from capnav.language.context import ContextConfig
from capnav.language.embedder import TextEmbedder
from capnav.language.room_prior import FLOOR, ROOM_PRIOR, room_posterior
from capnav.language.rooms import object_region, segment_rooms, walkable_domain
from capnav.mapping.cmap import CapNavMap


@dataclass(frozen=True)
class Place:
    """A point to look around from, and why it is worth it (``prior`` in [0, 1])."""

    xy: tuple[float, float]
    region: int  # room region of the map (-1: a frontier of unseen space)
    prior: float
    why: str


@dataclass(frozen=True)
class PlaceConfig:
    spacing: float = 3.5  # m between standing points of one region (a camera sees ~5 m)
    clearance: float = 0.45  # m a standing point keeps from walls and furniture
    room_weight: float = 0.5  # the room-type cue's share of the prior (the neighbours' the rest)
    floor: float = 0.25  # prior of a room where nothing speaks for the object: unlikely is not impossible


def room_places(cmap: CapNavMap, category: str | None, embedder: TextEmbedder,
                config: PlaceConfig | None = None) -> tuple[list[Place], NDArray[np.int32]]:
    """Standing points of every room region of ``cmap``, each with the region's prior for
    ``category``; and the region label of every grid cell (-1 outside the rooms)."""
    cfg = config or PlaceConfig()
    occ = cmap.occupancy
    spec = occ.spec
    objs = list(cmap.objects)
    lo = np.array([o.extent_min[:2] for o in objs], dtype=np.float64).reshape(-1, 2)
    hi = np.array([o.extent_max[:2] for o in objs], dtype=np.float64).reshape(-1, 2)
    ctx = ContextConfig()
    labels = segment_rooms(walkable_domain(occ, lo, hi), spec, ctx.door_width, ctx.min_room_m2)
    n = int(labels.max()) + 1
    if n <= 0:
        return [], labels
    member = np.array([object_region(labels, spec, a, b) for a, b in zip(lo, hi, strict=True)], dtype=np.int64)
    names = [o.label for o in objs]
    sims = _label_similarity(category, names, embedder)
    if len(sims):
        base = float(np.median(sims))
        sims = np.clip((sims - base) / max(1.0 - base, 1e-6), 0.0, 1.0)
    room_term = np.zeros(n)
    neigh = np.zeros(n)
    kinds: list[str] = []
    for k in range(n):
        here = [names[i] for i in np.flatnonzero(member == k)]
        room_term[k], kind = _room_term(category, here)
        kinds.append(kind)
        s = np.sort(sims[member == k])[::-1][:3]
        neigh[k] = float(np.clip(s.mean(), 0.0, 1.0)) if len(s) else 0.0
    if room_term.max() > 0:
        room_term = room_term / room_term.max()
    prior = cfg.floor + (1.0 - cfg.floor) * (cfg.room_weight * room_term + (1.0 - cfg.room_weight) * neigh)
    free = occ.cells == FREE
    clear = ndimage.distance_transform_edt(free) * spec.resolution
    out: list[Place] = []
    for k in range(n):
        cells = (labels == k) & (clear >= cfg.clearance)
        for rc in _spread(cells, clear, cfg.spacing / spec.resolution):
            xy = spec.to_world(np.asarray(rc))
            out.append(Place((float(xy[0]), float(xy[1])), k, float(prior[k]),
                             f"room region {k} ({kinds[k]}; room-type cue {room_term[k]:.2f}, "
                             f"neighbours cue {neigh[k]:.2f})"))
    return out, labels


def _room_term(category: str | None, labels: list[str]) -> tuple[float, str]:
    """E[P(category | room type)] over the region's room-type posterior, and the likeliest type."""
    post = room_posterior(labels)
    total = sum(post.values())
    known = category is not None and any(category in t for t in ROOM_PRIOR.values())
    like = {t: (ROOM_PRIOR[t].get(category, FLOOR) if known and category is not None else 1.0) for t in ROOM_PRIOR}
    if total <= 0:
        return float(np.mean(list(like.values()))), "no room cues"
    kind = max(post.items(), key=lambda kv: kv[1])
    return float(sum(post[t] * like[t] for t in ROOM_PRIOR)), f"likely a {kind[0]}, p {kind[1]:.2f}"


def _label_similarity(category: str | None, names: list[str], embedder: TextEmbedder) -> NDArray[np.float64]:
    """Cosine of each object label to the category in the text embedder's space (0 without one)."""
    if category is None or not names:
        return np.zeros(len(names))
    uniq = sorted(set(names))
    vecs = embedder.embed([category, *uniq]).astype(np.float64)
    vecs /= np.maximum(np.linalg.norm(vecs, axis=1, keepdims=True), 1e-9)
    cos = dict(zip(uniq, vecs[1:] @ vecs[0], strict=True))
    return np.array([cos[n] for n in names], dtype=np.float64)


def _spread(cells: NDArray[np.bool_], clear: NDArray[np.float64], spacing_cells: float) -> list[tuple[int, int]]:
    """The clearest cell of ``cells``, then the clearest cells at least ``spacing_cells`` from
    every point chosen so far (farthest-point style, the clearest first)."""
    rr, cc = np.nonzero(cells)
    if rr.size == 0:
        return []
    order = np.argsort(-clear[rr, cc], kind="stable")
    rr, cc = rr[order], cc[order]
    chosen: list[tuple[int, int]] = []
    left = np.ones(rr.size, bool)
    while left.any():
        i = int(np.flatnonzero(left)[0])
        chosen.append((int(rr[i]), int(cc[i])))
        left &= (rr - rr[i]) ** 2 + (cc - cc[i]) ** 2 >= spacing_cells**2
    return chosen
