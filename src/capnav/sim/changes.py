"""A later visit to the same apartment: seeded changes (objects moved, removed, new ones placed).

A home changes between two recordings: chairs are pushed around, a plant is carried to another
room, a lamp is thrown out, an armchair arrives, and a visit may not enter every room: a piece
carried into a room the later recording never enters (``hidden``) is somewhere no frame of that
visit saw, which only a search finds. ``apply_changes`` turns visit 1's apartment into visit 2's.
Objects keep their manifest ids across visits (the truth an evaluation compares against); new
objects take ids after the largest one. Every change is listed with its old and new pose
(``SceneManifest.changes``). The pipeline never reads this list: an update finds the changes from
the frames alone.
"""

from __future__ import annotations

import copy
import re
from dataclasses import dataclass

import numpy as np

from capnav.core.errors import InputError
from capnav.sim.apartment import REACH_RADIUS, Apartment, SceneObject, _appearance, _obstacles
from capnav.sim.manifest import ObjectChange
from capnav.sim.navgrid import NavGrid
from capnav.sim.placement import ROOM_PLANS, Placed, RoomFiller, door_zones
from capnav.sim.primitives import build_model
from capnav.sim.shapes import RectSet

#: What a person carries around or throws out (not the kitchen, the bed or the bathtub).
MOVABLE = ("chair", "armchair", "plant", "lamp", "stool", "ottoman", "coffee table", "nightstand", "tv",
           "bookshelf", "cabinet", "dresser", "desk", "table", "sofa")
#: What may arrive: anything movable that some room type plans for.
ADDABLE = ("chair", "armchair", "plant", "lamp", "stool", "ottoman", "bookshelf", "cabinet", "dresser", "desk")
MIN_MOVE = 1.0  # m: a move shorter than this is a nudge, not a change of place


#: The kinds of change a ``--changes`` spec counts, in its order.
KINDS = ("moved", "removed", "added", "hidden")


@dataclass(frozen=True)
class ChangeSpec:
    """How many objects to move, remove and add (``moved=3,removed=2,added=2``); ``hidden``: how many
    to carry into one room that the later visit's recording does not enter (``hidden=1``)."""

    moved: int = 0
    removed: int = 0
    added: int = 0
    hidden: int = 0

    def __post_init__(self) -> None:
        for k in KINDS:
            v = getattr(self, k)
            if not isinstance(v, int) or v < 0 or v > 50:
                raise InputError(f"--changes {k} must be an integer in 0..50, got {v!r}")

    @classmethod
    def parse(cls, text: str) -> ChangeSpec:
        """``"moved=3,removed=2,added=2"`` (any subset, any order)."""
        counts: dict[str, int] = {}
        for item in (s.strip() for s in text.split(",")):
            if not item:
                continue
            m = re.fullmatch(r"(\w+)\s*=\s*(\d+)", item)
            if m is None or m.group(1) not in KINDS:
                raise InputError(f"--changes: {item!r} is not KIND=COUNT with KIND one of {', '.join(KINDS)} "
                                 "(e.g. moved=3,removed=2,added=2)")
            if m.group(1) in counts:
                raise InputError(f"--changes: {m.group(1)} is given twice")
            counts[m.group(1)] = int(m.group(2))
        return cls(**counts)

    @property
    def total(self) -> int:
        return self.moved + self.removed + self.added + self.hidden

    def __str__(self) -> str:
        text = f"moved={self.moved},removed={self.removed},added={self.added}"
        return text + (f",hidden={self.hidden}" if self.hidden else "")  # older specs keep their text


def _placed(o: SceneObject) -> Placed:
    return Placed(o.category, o.model, o.x, o.y, o.yaw, o.room)


def _pose(o: SceneObject) -> tuple[float, float, float]:
    return (float(o.x), float(o.y), float(o.yaw))


def _reachable(apt: Apartment, items: list[SceneObject], o: SceneObject) -> bool:
    """``o`` can be reached and every other object still can (the new piece blocks no passage)."""
    grid = NavGrid(_obstacles(apt.wall_rects, items), apt.bounds, apt.config.agent.radius, apt.config.nav_resolution)
    pts = grid.free_points()
    if len(pts) == 0:
        return False
    for q in items:
        rs = RectSet.from_lists([(q.x, q.y)], [q.model.size[:2]], [q.yaw])
        near = np.abs(pts[:, 0] - q.x) + np.abs(pts[:, 1] - q.y) < REACH_RADIUS + sum(q.model.size[:2])
        if not near.any() or rs.min_distance(pts[near]).min() > REACH_RADIUS:
            return False
    return True


def _place(apt: Apartment, items: list[SceneObject], o: SceneObject, room: int, rng: np.random.Generator,
           away_from: tuple[float, float] | None) -> SceneObject | None:
    """``o`` (a copy) at a free spot of ``room`` (along a wall, or in the middle), or None."""
    r = apt.plan.rooms[room]
    doors = [d for d in apt.plan.doors if room in d.rooms]
    others = [_placed(q) for q in items if q is not o]
    filler = RoomFiller(rng, r.shrink(apt.config.layout.wall_thickness / 2), room, door_zones(r, doors), others)
    for _ in range(6):
        rule = ("wall", "corner", "center")[int(rng.integers(3))]
        cand = filler.place(o.category, o.model, rule)
        if cand is None:
            continue
        if away_from is not None and np.hypot(cand.x - away_from[0], cand.y - away_from[1]) < MIN_MOVE:
            continue
        new = copy.copy(o)
        new.x, new.y, new.yaw, new.room = cand.x, cand.y, cand.yaw, room
        trial = [new if q is o else q for q in items] if any(q is o for q in items) else [*items, new]
        if _reachable(apt, trial, new):
            return new
    return None


def apply_changes(apt: Apartment, spec: ChangeSpec, seed: int, visit: int = 2) -> tuple[Apartment,
                                                                                          list[ObjectChange]]:
    """Visit ``visit``'s apartment: ``spec`` changes drawn from ``(seed, visit)``; the list of them."""
    rng = np.random.default_rng([apt.seed, seed, visit, 0xC4A])
    items = list(apt.objects)
    changes: list[ObjectChange] = []
    room_of = {k: name for k, name in enumerate(apt.plan.types)}
    # With hidden objects, one room is left out of the visit: nothing else changes in it or moves into
    # it (a change there no frame sees); without, the draws are those of every earlier dataset.
    left_out = _left_out_room(apt, spec.hidden, seed, visit)
    movable = [o for o in items if o.category in MOVABLE and o.room != left_out]
    if spec.moved + spec.removed > len(movable):
        raise InputError(f"apartment seed {apt.seed} has {len(movable)} movable objects; cannot move "
                         f"{spec.moved} and remove {spec.removed}")
    picks = [movable[int(i)] for i in rng.permutation(len(movable))]
    n_moved = 0
    used: set[int] = set()
    for o in picks:
        if n_moved == spec.moved:
            break
        rooms = [o.room] if rng.random() < 0.5 else [k for k in rng.permutation(len(apt.plan.rooms))]
        if o.room not in rooms:
            rooms.append(o.room)
        rooms = [k for k in rooms if k != left_out]
        for room in rooms:
            new = _place(apt, items, o, int(room), rng, away_from=(o.x, o.y))
            if new is not None:
                changes.append(ObjectChange(kind="moved", id=o.id, category=o.category, old_pose=_pose(o),
                                            new_pose=_pose(new), old_room=f"room{o.room}",
                                            new_room=f"room{new.room}"))
                items = [new if q is o else q for q in items]
                used.add(o.id)
                n_moved += 1
                break
    if n_moved < spec.moved:
        raise InputError(f"apartment seed {apt.seed}: found free places for {n_moved} of {spec.moved} moves")
    gone = [o for o in picks if o.id not in used][: spec.removed]
    for o in gone:
        changes.append(ObjectChange(kind="removed", id=o.id, category=o.category, old_pose=_pose(o),
                                    old_room=f"room{o.room}"))
    items = [q for q in items if q.id not in {o.id for o in gone}]
    next_id = max((o.id for o in apt.objects), default=0) + 1
    looks: dict[str, list[str]] = {}
    for q in items:
        looks.setdefault(q.category, []).append(q.color_name)
    added = 0
    for _ in range(spec.added * 10):
        if added == spec.added:
            break
        room = int(rng.integers(len(apt.plan.rooms)))
        if room == left_out:
            continue
        cats = [c for c, _, _, _ in ROOM_PLANS[room_of[room]] if c in ADDABLE]
        if not cats:
            continue
        cat = cats[int(rng.integers(len(cats)))]
        name, material, roles = _appearance(cat, rng, looks)
        o = SceneObject(next_id, cat, build_model(cat, rng), 0.0, 0.0, 0.0, room, name, material, roles)
        new = _place(apt, items, o, room, rng, away_from=None)
        if new is None:
            continue
        items.append(new)
        changes.append(ObjectChange(kind="added", id=new.id, category=cat, new_pose=_pose(new),
                                    new_room=f"room{room}"))
        next_id += 1
        added += 1
    if added < spec.added:
        raise InputError(f"apartment seed {apt.seed}: found free places for {added} of {spec.added} new objects")
    if spec.hidden:
        assert left_out is not None
        items, hidden = _hide(apt, items, spec.hidden, left_out, {c.id for c in changes}, seed, visit)
        changes += hidden
    items.sort(key=lambda q: q.id)
    out = Apartment(apt.seed, apt.config, apt.plan, items, apt.wall_rects, apt.wall_faces, apt.floor_styles,
                    apt.wall_colors)
    return out, changes


def _hide_rng(apt: Apartment, seed: int, visit: int) -> np.random.Generator:
    """The hidden objects' own random stream: a spec without ``hidden`` draws exactly as before."""
    return np.random.default_rng([apt.seed, seed, visit, 0xC4B])


def _left_out_room(apt: Apartment, hidden: int, seed: int, visit: int) -> int | None:
    """The room a visit with ``hidden`` objects leaves out: one door (no way between two other rooms
    passes through it), not the room a recording starts in (the living room); None without hidden."""
    if not hidden:
        return None
    plan = apt.plan
    start = plan.types.index("living room") if "living room" in plan.types else 0
    leaves = [k for k in range(len(plan.rooms)) if k != start and sum(k in d.rooms for d in plan.doors) == 1]
    if not leaves:
        raise InputError(f"apartment seed {apt.seed} has no room with a single door to leave out of visit "
                         f"{visit}; cannot hide {hidden} objects there")
    return int(leaves[int(_hide_rng(apt, seed, visit).integers(len(leaves)))])


def _hide(apt: Apartment, items: list[SceneObject], n: int, room: int, changed: set[int], seed: int,
          visit: int) -> tuple[list[SceneObject], list[ObjectChange]]:
    """``n`` movable objects carried into ``room``, the one the visit leaves out (kind ``hidden``)."""
    rng = _hide_rng(apt, seed, visit + 1000)
    movable = [o for o in items if o.category in MOVABLE and o.id not in changed and o.room != room]
    out: list[ObjectChange] = []
    for k in rng.permutation(len(movable)):
        if len(out) == n:
            break
        o = movable[int(k)]
        new = _place(apt, items, o, room, rng, away_from=(o.x, o.y))
        if new is None:
            continue
        items = [new if q is o else q for q in items]
        out.append(ObjectChange(kind="hidden", id=o.id, category=o.category, old_pose=_pose(o),
                                new_pose=_pose(new), old_room=f"room{o.room}", new_room=f"room{room}"))
    if len(out) < n:
        raise InputError(f"apartment seed {apt.seed}: found free places for {len(out)} of {n} hidden objects "
                         f"in room{room}")
    return items, out


def left_out_rooms(changes: list[ObjectChange]) -> set[int]:
    """The rooms a visit's recording does not enter: where its ``hidden`` objects were carried."""
    return {int(c.new_room.removeprefix("room")) for c in changes if c.kind == "hidden" and c.new_room}


def hidden_ids(changes: list[ObjectChange]) -> set[int]:
    """The objects a visit's recording must never show (a frame looking at one through the door of
    the room it was left in is not recorded)."""
    return {c.id for c in changes if c.kind == "hidden"}
