"""Procedural floor plans: a rectangle split into 3-7 rooms (BSP), doors on shared walls."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from capnav.core.errors import InputError
from capnav.sim.config import LayoutConfig


@dataclass(frozen=True)
class Rect:
    x0: float
    y0: float
    x1: float
    y1: float

    @property
    def w(self) -> float:
        return self.x1 - self.x0

    @property
    def h(self) -> float:
        return self.y1 - self.y0

    @property
    def area(self) -> float:
        return self.w * self.h

    @property
    def center(self) -> tuple[float, float]:
        return ((self.x0 + self.x1) / 2.0, (self.y0 + self.y1) / 2.0)

    def shrink(self, d: float) -> Rect:
        return Rect(self.x0 + d, self.y0 + d, self.x1 - d, self.y1 - d)

    def polygon(self) -> list[tuple[float, float]]:
        return [(self.x0, self.y0), (self.x1, self.y0), (self.x1, self.y1), (self.x0, self.y1)]


@dataclass(frozen=True)
class DoorSpec:
    rooms: tuple[int, int]
    axis: str  # "x": the door lies on a wall of constant x; "y": constant y
    coord: float  # x (axis "x") or y (axis "y") of the shared wall line
    lo: float  # opening interval along the wall
    hi: float

    @property
    def center(self) -> tuple[float, float]:
        mid = (self.lo + self.hi) / 2.0
        return (self.coord, mid) if self.axis == "x" else (mid, self.coord)

    @property
    def width(self) -> float:
        return self.hi - self.lo


@dataclass
class FloorPlan:
    bounds: Rect
    rooms: list[Rect]
    types: list[str]
    doors: list[DoorSpec] = field(default_factory=list)

    def room_of(self, x: float, y: float) -> int:
        for i, r in enumerate(self.rooms):
            if r.x0 <= x <= r.x1 and r.y0 <= y <= r.y1:
                return i
        return -1


def _split(rng: np.random.Generator, rects: list[Rect], n: int, min_side: float) -> list[Rect]:
    """Binary space partition: split the largest splittable rectangle along its long side."""
    while len(rects) < n:
        order = sorted(range(len(rects)), key=lambda i: -rects[i].area)
        for i in order:
            r = rects[i]
            long_x = r.w >= r.h
            length = r.w if long_x else r.h
            if length < 2 * min_side:
                continue
            lo, hi = max(0.35, min_side / length), min(0.65, 1.0 - min_side / length)
            t = float(np.round(rng.uniform(lo, hi) * length, 1))  # 10 cm grid keeps walls tidy
            t = min(max(t, min_side), length - min_side)
            if long_x:
                a, b = Rect(r.x0, r.y0, r.x0 + t, r.y1), Rect(r.x0 + t, r.y0, r.x1, r.y1)
            else:
                a, b = Rect(r.x0, r.y0, r.x1, r.y0 + t), Rect(r.x0, r.y0 + t, r.x1, r.y1)
            rects = [*rects[:i], a, b, *rects[i + 1:]]
            break
        else:
            raise InputError(f"cannot split the apartment into {n} rooms of side >= {min_side} m")
    return rects


#: Room types of an n-room plan: the first 7 as the benchmark's apartments, then houses grow by
#: this cycle (more bedrooms, hallways joining them, bathrooms, studies, a second living area).
_BASE_TYPES = ["living room", "kitchen", "bedroom", "bathroom", "office", "bedroom", "hallway"]
_MORE_TYPES = ["bedroom", "hallway", "bathroom", "office", "bedroom", "living room", "hallway", "bathroom", "kitchen"]


def room_types(n: int) -> list[str]:
    """The multiset of room types of an n-room floor plan."""
    small = {3: ["living room", "bedroom", "bathroom"], 4: ["living room", "kitchen", "bedroom", "bathroom"],
             5: ["living room", "kitchen", "bedroom", "bathroom", "office"],
             6: ["living room", "kitchen", "bedroom", "bathroom", "office", "bedroom"]}
    if n in small:
        return list(small[n])
    return _BASE_TYPES + [_MORE_TYPES[i % len(_MORE_TYPES)] for i in range(n - 7)]


def _assign_types(rects: list[Rect], rng: np.random.Generator) -> list[str]:
    """Living rooms take the largest rooms, hallways the most elongated, bathrooms the smallest."""
    n = len(rects)
    wanted = room_types(n)
    types = [""] * n
    by_area = sorted(range(n), key=lambda i: -rects[i].area)
    rest = list(by_area)
    for _ in range(wanted.count("living room")):
        types[rest[0]] = "living room"
        rest.pop(0)
    for _ in range(wanted.count("hallway")):
        hall = max(rest, key=lambda i: max(rects[i].w, rects[i].h) / min(rects[i].w, rects[i].h))
        types[hall] = "hallway"
        rest.remove(hall)
    for _ in range(wanted.count("bathroom")):
        bath = rest[-1]  # the smallest
        types[bath] = "bathroom"
        rest.remove(bath)
    others = [t for t in wanted if t not in ("living room", "hallway", "bathroom")]
    perm = rng.permutation(len(rest))
    for t, k in zip(others, perm, strict=True):
        types[rest[int(k)]] = t
    return types


def _shared_wall(a: Rect, b: Rect, eps: float = 1e-6) -> tuple[str, float, float, float] | None:
    """(axis, coord, lo, hi) of the wall two rooms share, if any."""
    for xa, xb in ((a.x1, b.x0), (a.x0, b.x1)):
        if abs(xa - xb) < eps:
            lo, hi = max(a.y0, b.y0), min(a.y1, b.y1)
            if hi > lo:
                return ("x", xa, lo, hi)
    for ya, yb in ((a.y1, b.y0), (a.y0, b.y1)):
        if abs(ya - yb) < eps:
            lo, hi = max(a.x0, b.x0), min(a.x1, b.x1)
            if hi > lo:
                return ("y", ya, lo, hi)
    return None


def _doors(rects: list[Rect], types: list[str], cfg: LayoutConfig, rng: np.random.Generator) -> list[DoorSpec]:
    n = len(rects)
    margin = 0.35 + cfg.wall_thickness  # keep the opening away from the room corners
    need = cfg.door_width + 2 * margin
    edges: list[tuple[int, int, tuple[str, float, float, float]]] = []
    for i in range(n):
        for j in range(i + 1, n):
            s = _shared_wall(rects[i], rects[j])
            if s is not None and s[3] - s[2] >= need:
                edges.append((i, j, s))
    # Random spanning tree, preferring edges that touch the living room / hallway (hubs).
    hub = {k for k, t in enumerate(types) if t in ("living room", "hallway")}
    keys = rng.random(len(edges)) - np.array([0.5 if (i in hub or j in hub) else 0.0 for i, j, _ in edges])
    parent = list(range(n))

    def find(k: int) -> int:
        while parent[k] != k:
            parent[k] = parent[parent[k]]
            k = parent[k]
        return k

    chosen: list[tuple[int, int, tuple[str, float, float, float]]] = []
    spare: list[tuple[int, int, tuple[str, float, float, float]]] = []
    for e in (edges[k] for k in np.argsort(keys, kind="stable")):
        ri, rj = find(e[0]), find(e[1])
        if ri != rj:
            parent[ri] = rj
            chosen.append(e)
        elif "bathroom" not in (types[e[0]], types[e[1]]):
            spare.append(e)
    if len({find(k) for k in range(n)}) != 1:
        raise InputError("floor plan is not connected (no wall long enough for a door)")
    for e in spare:
        if rng.random() < cfg.extra_door_prob:
            chosen.append(e)
    doors = []
    for i, j, (axis, coord, lo, hi) in chosen:
        a, b = lo + margin + cfg.door_width / 2, hi - margin - cfg.door_width / 2
        c = float(np.round(rng.uniform(a, max(a, b)), 2))
        doors.append(DoorSpec((i, j), axis, coord, c - cfg.door_width / 2, c + cfg.door_width / 2))
    return doors


def generate_floorplan(seed: int, cfg: LayoutConfig) -> FloorPlan:
    """Deterministic floor plan for ``seed``: rooms tile a rectangle, doors connect them all."""
    rng = np.random.default_rng([seed, 1])
    n = cfg.rooms if cfg.rooms is not None else int(rng.integers(cfg.min_rooms, cfg.max_rooms + 1))
    for _attempt in range(50):
        area = n * rng.uniform(*cfg.room_area)
        aspect = rng.uniform(1.1, 1.6)
        w = float(np.round(np.sqrt(area * aspect), 1))
        h = float(np.round(area / w, 1))
        try:
            rects = _split(rng, [Rect(0.0, 0.0, w, h)], n, cfg.min_room_side)
            types = _assign_types(rects, rng)
            doors = _doors(rects, types, cfg, rng)
        except InputError:
            continue
        return FloorPlan(Rect(0.0, 0.0, w, h), rects, types, doors)
    raise InputError(f"could not generate a floor plan with {n} rooms for seed {seed}")
