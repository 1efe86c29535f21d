"""A whole procedural apartment from a seed: floor plan, walls, furniture, and its manifest."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from capnav.core.categories import BY_NAME
from capnav.core.errors import InputError
from capnav.sim.config import SimConfig
from capnav.sim.layout import FloorPlan, Rect, generate_floorplan
from capnav.sim.manifest import Door, ItemInstance, ObjectInstance, Room, SceneManifest
from capnav.sim.navgrid import NavGrid
from capnav.sim.palette import (
    CATEGORY_STYLE,
    COLORS,
    ROLE_COLORS,
    ROOM_FLOORS,
    ROOM_WALLS,
    UPHOLSTERY,
    WOODS,
)
from capnav.sim.placement import OPEN_KITCHEN, ROOM_PLANS, Placed, RoomFiller, door_zones
from capnav.sim.primitives import Model, build_model
from capnav.sim.shapes import RectSet, rect_corners

RGB = tuple[int, int, int]
REACH_RADIUS = 1.0  # an object is reachable when a navigable cell lies within this of its footprint


@dataclass
class SceneObject:
    """A placed piece of furniture with its appearance; ``id`` is the manifest / gt_instance id."""

    id: int
    category: str
    model: Model
    x: float
    y: float
    yaw: float
    room: int
    color_name: str
    material: str
    roles: dict[str, RGB]
    source: str = "primitive"
    license: str = "CC0-1.0"
    mesh: object | None = None  # a furniture-source specific mesh description (sh3d)

    @property
    def pose(self) -> NDArray[np.float64]:
        c, s = np.cos(self.yaw), np.sin(self.yaw)
        T = np.eye(4)
        T[:2, :2] = [[c, -s], [s, c]]
        T[0, 3], T[1, 3] = self.x, self.y
        return T

    def footprint(self) -> NDArray[np.float64]:
        return rect_corners((self.x, self.y), self.model.size[:2], self.yaw)


@dataclass(frozen=True)
class WallFace:
    """A vertical quad: from (x0, y0) to (x1, y1) on the floor, up to the wall height, facing ``normal``."""

    room: int
    p0: tuple[float, float]
    p1: tuple[float, float]
    normal: tuple[float, float]


@dataclass
class Apartment:
    seed: int
    config: SimConfig
    plan: FloorPlan
    objects: list[SceneObject]
    wall_rects: RectSet
    wall_faces: list[WallFace]
    floor_styles: list[tuple[str, RGB]]
    wall_colors: list[RGB]
    items: list[SceneObject] = field(default_factory=list)  # small things on furniture (opt-in, surface_items)
    manifest: SceneManifest = field(init=False)

    def __post_init__(self) -> None:
        self.manifest = _manifest(self)

    def obstacles(self) -> RectSet:
        """Walls and furniture footprints as oriented rectangles (the agent's collision geometry)."""
        return _obstacles(self.wall_rects, self.objects)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        b = self.plan.bounds
        return (b.x0, b.y0, b.x1, b.y1)


def _obstacles(walls: RectSet, objects: list[SceneObject] | list[Placed]) -> RectSet:
    if not objects:
        return walls
    extra = RectSet.from_lists([(o.x, o.y) for o in objects], [o.model.size[:2] for o in objects],
                               [o.yaw for o in objects])
    return RectSet(np.vstack([walls.center, extra.center]), np.vstack([walls.half, extra.half]),
                   np.concatenate([walls.cos, extra.cos]), np.concatenate([walls.sin, extra.sin]))


def _walls(plan: FloorPlan, t: float) -> tuple[RectSet, list[WallFace]]:
    """Each room owns a half-thickness slab along each edge (door intervals removed)."""
    h = t / 2
    centers, sizes, faces = [], [], []
    for k, r in enumerate(plan.rooms):
        inner = r.shrink(h)
        for side in ("south", "north", "west", "east"):
            along_x = side in ("south", "north")
            line = {"south": r.y0, "north": r.y1, "west": r.x0, "east": r.x1}[side]
            lo, hi = (r.x0, r.x1) if along_x else (r.y0, r.y1)
            gaps = sorted((d.lo, d.hi) for d in plan.doors if k in d.rooms
                          and d.axis == ("y" if along_x else "x") and abs(d.coord - line) < 1e-6)
            segs, cur = [], lo
            for a, b in gaps:
                if a > cur:
                    segs.append((cur, a))
                cur = max(cur, b)
            if cur < hi:
                segs.append((cur, hi))
            sign = 1.0 if side in ("south", "west") else -1.0
            face = line + sign * h
            ilo, ihi = (inner.x0, inner.x1) if along_x else (inner.y0, inner.y1)
            for a, b in segs:
                mid, length = (a + b) / 2, b - a
                if along_x:
                    centers.append((mid, line + sign * h / 2))
                    sizes.append((length, h))
                else:
                    centers.append((line + sign * h / 2, mid))
                    sizes.append((h, length))
                fa, fb = max(a, ilo), min(b, ihi)
                if fb - fa < 1e-6:
                    continue
                if along_x:
                    p0, p1, n = (fa, face), (fb, face), (0.0, sign)
                else:
                    p0, p1, n = (face, fa), (face, fb), (sign, 0.0)
                faces.append(WallFace(k, p0, p1, n))
    for d in plan.doors:  # jambs: the wall's cut ends at both sides of the opening, each room its half
        for room in d.rooms:
            r = plan.rooms[room]
            sgn = 1.0 if (r.x0 if d.axis == "x" else r.y0) >= d.coord - 1e-9 else -1.0  # room beyond +coord?
            lo, hi = sorted((d.coord, d.coord + sgn * h))
            for end, nsign in ((d.lo, 1.0), (d.hi, -1.0)):
                if d.axis == "x":
                    faces.append(WallFace(room, (lo, end), (hi, end), (0.0, nsign)))
                else:
                    faces.append(WallFace(room, (end, lo), (end, hi), (nsign, 0.0)))
    return RectSet.from_lists(centers, sizes, [0.0] * len(centers)), faces


def _shade(rgb: RGB, f: float) -> RGB:
    return (int(min(255, rgb[0] * f)), int(min(255, rgb[1] * f)), int(min(255, rgb[2] * f)))


def _appearance(cat: str, rng: np.random.Generator, used: dict[str, list[str]], near_prob: float = 0.0
                ) -> tuple[str, str, dict[str, RGB]]:
    """Colour name, material and part colours of a new instance. With ``near_prob`` > 0 another
    instance of a category may take a shade of an earlier one's colour (same name, a lookalike)."""
    colors, materials = CATEGORY_STYLE[cat]
    near = near_prob > 0.0 and bool(used.get(cat)) and rng.random() < near_prob
    if near:
        name = used[cat][int(rng.integers(len(used[cat])))]
    else:
        fresh = [c for c in colors if c not in used.get(cat, [])] or colors
        name = fresh[int(rng.integers(len(fresh)))]
    used.setdefault(cat, []).append(name)
    material = materials[int(rng.integers(len(materials)))]
    main = _shade(COLORS[name], float(rng.uniform(0.88, 1.12))) if near else COLORS[name]
    roles: dict[str, RGB] = dict(ROLE_COLORS)
    roles["main"] = main
    roles["accent"] = _shade(main, 1.15 if cat in ("sofa", "armchair", "ottoman") else 0.85)
    wood = COLORS[WOODS[int(rng.integers(4))]]
    if cat in ("bed", "sink"):
        roles["accent"] = wood
    if cat == "chair" and material == "wood":
        roles["accent"] = COLORS[UPHOLSTERY[int(rng.integers(len(UPHOLSTERY)))]]
    if cat == "counter":
        roles["accent"] = [(236, 234, 228), (40, 40, 42), (150, 150, 150), (200, 190, 170)][int(rng.integers(4))]
    roles["legs"] = ROLE_COLORS["metal"] if material in ("metal", "stainless steel") else \
        (wood if rng.random() < 0.6 else ROLE_COLORS["dark"])
    if cat in ("table", "coffee table", "desk", "nightstand", "stool", "chair") and material == "wood":
        roles["legs"] = main
    return name, material, roles


#: Small pieces the large preset scatters in front of furniture (partial occlusion, lookalikes).
_CLUTTER = ("plant", "ottoman", "stool")


def _fill(plan: FloorPlan, cfg: SimConfig, rng: np.random.Generator) -> list[tuple[Placed, str, str, dict[str, RGB]]]:
    h = cfg.layout.wall_thickness / 2
    placed: list[Placed] = []
    looks: list[tuple[str, str, dict[str, RGB]]] = []
    used: dict[str, list[str]] = {}
    has_kitchen = "kitchen" in plan.types
    for k, (room, rtype) in enumerate(zip(plan.rooms, plan.types, strict=True)):
        doors = [d for d in plan.doors if k in d.rooms]
        filler = RoomFiller(rng, room.shrink(h), k, door_zones(room, doors), placed)
        plan_items = list(ROOM_PLANS[rtype])
        if rtype == "living room" and not has_kitchen:
            plan_items = plan_items[:4] + OPEN_KITCHEN + plan_items[4:]
        fc = cfg.furnish
        if fc.clutter_per_room[1] > 0:  # small pieces in front of this room's furniture
            n_clutter = int(rng.integers(fc.clutter_per_room[0], fc.clutter_per_room[1] + 1))
            hosts = [c for c, _, _, r in plan_items if r in ("wall", "corner") and c not in _CLUTTER]
            for _ in range(n_clutter if hosts else 0):
                host = hosts[int(rng.integers(len(hosts)))]
                plan_items.append((_CLUTTER[int(rng.integers(len(_CLUTTER)))], 1, 1, f"front:{host}"))
        for cat, lo, hi, rule in plan_items:
            if fc.count_scale != 1.0:
                hi = max(lo, round(hi * fc.count_scale))
            count = int(rng.integers(lo, hi + 1))
            if fc.max_per_category is not None:
                count = min(count, fc.max_per_category - sum(p.category == cat for p in placed))
            shared: tuple[Model, tuple[str, str, dict[str, RGB]]] | None = None
            for _ in range(count):
                if shared is not None and rule.startswith(("around:", "front:counter")):
                    model, look = shared  # a matching set (dining chairs, bar stools)
                else:
                    model = build_model(cat, rng)
                    look = _appearance(cat, rng, used, fc.near_color_prob)
                    shared = (model, look)
                cand = filler.place(cat, model, rule)
                if cand is not None:
                    placed.append(cand)
                    looks.append(look)
    return [(p, *lk) for p, lk in zip(placed, looks, strict=True)]


def _prune_unreachable(items: list[SceneObject], walls: RectSet, bounds: tuple[float, float, float, float],
                       cfg: SimConfig) -> list[SceneObject]:
    """Drop objects the agent cannot get within REACH_RADIUS of, until every object is reachable."""
    while True:
        grid = NavGrid(_obstacles(walls, items), bounds, cfg.agent.radius, cfg.nav_resolution)
        pts = grid.free_points()
        if len(pts) == 0:
            raise InputError("apartment has no navigable space")
        bad = []
        for i, o in enumerate(items):
            rs = RectSet.from_lists([(o.x, o.y)], [o.model.size[:2]], [o.yaw])
            near = np.abs(pts[:, 0] - o.x) + np.abs(pts[:, 1] - o.y) < REACH_RADIUS + sum(o.model.size[:2])
            if not near.any() or rs.min_distance(pts[near]).min() > REACH_RADIUS:
                bad.append(i)
        if not bad:
            return items
        bad.sort(key=lambda i: -items[i].model.size[0] * items[i].model.size[1])  # largest first (stable)
        gone = set(bad[:cfg.furnish.prune_batch])
        items = [o for i, o in enumerate(items) if i not in gone]


def _drop_orphans(items: list[SceneObject]) -> list[SceneObject]:
    """Nightstands only make sense beside a bed of their room."""
    bed_rooms = {o.room for o in items if o.category == "bed"}
    return [o for o in items if o.category != "nightstand" or o.room in bed_rooms]


def generate_apartment(seed: int, cfg: SimConfig) -> Apartment:
    """Deterministic apartment for ``seed``: every object reachable, some category with >= 3 instances."""
    if not isinstance(seed, (int, np.integer)) or isinstance(seed, bool) or seed < 0 or seed >= 2**32:
        raise InputError(f"seed must be an integer in [0, 2**32), got {seed!r}")
    seed = int(seed)
    plan = generate_floorplan(seed, cfg.layout)
    walls, faces = _walls(plan, cfg.layout.wall_thickness)
    bounds = (plan.bounds.x0, plan.bounds.y0, plan.bounds.x1, plan.bounds.y1)
    srng = np.random.default_rng([seed, 3])
    floors = [ROOM_FLOORS[t][int(srng.integers(len(ROOM_FLOORS[t])))] for t in plan.types]
    wall_colors = [ROOM_WALLS[int(srng.integers(len(ROOM_WALLS)))] for _ in plan.types]
    best: list[SceneObject] | None = None
    best_lost = 10**9
    for attempt in range(12):  # keep the furnishing that loses fewest objects to the reachability check
        rng = np.random.default_rng([seed, 2, attempt])
        placed = [SceneObject(0, p.category, p.model, p.x, p.y, p.yaw, p.room, name, material, roles)
                  for p, name, material, roles in _fill(plan, cfg, rng)]
        items = _drop_orphans(_prune_unreachable(placed, walls, bounds, cfg))
        counts: dict[str, int] = {}
        for o in items:
            counts[o.category] = counts.get(o.category, 0) + 1
        if not counts or max(counts.values()) < 3:
            continue
        lost = len(placed) - len(items)
        if lost < best_lost:
            best, best_lost = items, lost
        if lost <= cfg.furnish.accept_lost:
            break
    if best is None:
        raise InputError(f"seed {seed}: could not furnish the apartment with a category of >= 3 instances")
    items = best
    for i, o in enumerate(items):
        o.id = i + 1
    return Apartment(seed, cfg, plan, items, walls, faces, floors, wall_colors)


def _model_id(o: SceneObject) -> str:
    mesh_id = getattr(o.mesh, "id", None)
    return f"sh3d:{mesh_id}" if mesh_id is not None else f"{o.source}:{o.category}/{o.model.variant}"


def _shape(o: SceneObject) -> str:
    name = getattr(o.mesh, "name", None)
    return str(name).lower() if name is not None else o.model.variant


def _manifest(apt: Apartment) -> SceneManifest:
    plan = apt.plan
    room_ids = [f"room{k}" for k in range(len(plan.rooms))]
    objs = []
    for o in apt.objects:
        fp = o.footprint()
        objs.append(ObjectInstance(
            id=o.id, category=o.category, category_id=BY_NAME[o.category].id, color_name=o.color_name,
            color_rgb=o.roles["main"], material=o.material, shape=_shape(o),
            size=(o.model.size[0], o.model.size[1], o.model.size[2]),
            center=(o.x, o.y, o.model.size[2] / 2), yaw=float(o.yaw),
            footprint=[(float(x), float(y)) for x, y in fp], room=room_ids[o.room],
            model=_model_id(o), license=o.license))
    rooms = [Room(id=room_ids[k], name=t, polygon=r.polygon()) for k, (r, t) in enumerate(
        zip(plan.rooms, plan.types, strict=True))]
    doors = [Door(rooms=(room_ids[d.rooms[0]], room_ids[d.rooms[1]]), center=d.center, width=d.width)
             for d in plan.doors]
    items = [ItemInstance(
        id=o.id, category=o.category, color_name=o.color_name, size=o.model.size,
        center=(o.x, o.y, float(getattr(o, "base", 0.0)) + o.model.size[2] / 2), yaw=float(o.yaw),
        footprint=[(float(x), float(y)) for x, y in o.footprint()], room=room_ids[o.room],
        support=int(getattr(o, "support", 0))) for o in apt.items]
    b: Rect = plan.bounds
    return SceneManifest(seed=apt.seed, bounds=(b.x0, b.y0, b.x1, b.y1), wall_height=apt.config.layout.wall_height,
                         rooms=rooms, doors=doors, objects=objs, items=items or None)
