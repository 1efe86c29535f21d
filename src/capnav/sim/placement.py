"""Plausible furniture placement: wall-backed pieces, groups around anchors, free door zones.

Each room type has a plan of (category, min, max, rule). Rules: "wall" (back to a wall), "corner",
"center", and anchored ones: "front:<cat>" (in front of it, facing it), "around:<cat>" (chairs
around a table), "beside:<cat>" (nightstands at the bed head), "near:<cat>" (armchair by a coffee
table). Candidates are rejected if they leave the room, overlap another footprint or a door zone.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from capnav.sim.layout import DoorSpec, Rect
from capnav.sim.primitives import Model
from capnav.sim.shapes import rect_corners, rects_overlap, rot2

Plan = list[tuple[str, int, int, str]]

ROOM_PLANS: dict[str, Plan] = {
    "living room": [("sofa", 1, 2, "wall"), ("coffee table", 1, 1, "front:sofa"),
                    ("armchair", 1, 3, "near:coffee table"),
                    ("tv", 1, 1, "wall"), ("lamp", 1, 2, "corner"), ("plant", 1, 2, "corner"),
                    ("bookshelf", 0, 1, "wall"), ("ottoman", 0, 1, "center"), ("cabinet", 0, 1, "wall")],
    "kitchen": [("refrigerator", 1, 1, "corner"), ("stove", 1, 1, "wall"), ("counter", 1, 2, "wall"),
                ("table", 1, 1, "center"), ("chair", 2, 4, "around:table"), ("stool", 0, 2, "front:counter"),
                ("washing machine", 0, 1, "wall"), ("plant", 0, 1, "corner"), ("cabinet", 0, 1, "wall")],
    "bedroom": [("bed", 1, 1, "wall"), ("nightstand", 1, 2, "beside:bed"), ("wardrobe", 1, 1, "wall"),
                ("dresser", 0, 1, "wall"), ("lamp", 0, 1, "corner"), ("plant", 0, 1, "corner"),
                ("armchair", 0, 1, "corner"), ("desk", 0, 1, "wall"), ("chair", 0, 1, "front:desk")],
    "bathroom": [("toilet", 1, 1, "wall"), ("sink", 1, 2, "wall"), ("bathtub", 0, 1, "corner"),
                 ("washing machine", 0, 1, "wall"), ("cabinet", 0, 1, "wall"), ("plant", 0, 1, "corner")],
    "office": [("desk", 1, 2, "wall"), ("chair", 1, 2, "front:desk"), ("bookshelf", 1, 2, "wall"),
               ("lamp", 0, 1, "corner"), ("plant", 0, 2, "corner"), ("cabinet", 0, 1, "wall"),
               ("armchair", 0, 1, "corner")],
    "hallway": [("cabinet", 0, 1, "wall"), ("dresser", 0, 1, "wall"), ("plant", 1, 2, "corner"),
                ("lamp", 0, 1, "corner"), ("ottoman", 0, 1, "wall"), ("stool", 0, 1, "wall")],
}
# An apartment without a kitchen gets an open-plan kitchen corner in its living room.
OPEN_KITCHEN: Plan = [("refrigerator", 1, 1, "corner"), ("stove", 1, 1, "wall"), ("counter", 1, 1, "wall"),
                      ("stool", 1, 3, "front:counter")]


@dataclass
class Placed:
    """A placed footprint: centre (x, y), yaw of the local x axis, full (w, d) of the model."""

    category: str
    model: Model
    x: float
    y: float
    yaw: float
    room: int
    group: int = -1  # index of the anchor it was placed against (or -1)
    corners: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.corners = rect_corners((self.x, self.y), self.model.size[:2], self.yaw)

    def local_to_world(self, lx: float, ly: float) -> tuple[float, float]:
        p = rot2(self.yaw) @ np.array([lx, ly]) + np.array([self.x, self.y])
        return float(p[0]), float(p[1])


# Pieces that only make sense next to their anchor (no fallback to a free wall spot).
_ANCHORED_ONLY = ("chair", "nightstand", "coffee table", "stool")

# Wall k of a room: (yaw that turns the front (+y) away from it, which side).
_WALL_YAW = {"south": 0.0, "north": np.pi, "west": -np.pi / 2, "east": np.pi / 2}


def door_zones(room: Rect, doors: list[DoorSpec], depth: float = 1.0) -> list[np.ndarray]:
    """Rectangles (4, 2) in front of each door, on this room's side, kept free of furniture."""
    zones = []
    for d in doors:
        (cx, cy), w = d.center, d.width + 0.3
        if d.axis == "x":
            sign = 1.0 if abs(cx - room.x0) < 1e-6 else -1.0
            if not (abs(cx - room.x0) < 1e-6 or abs(cx - room.x1) < 1e-6) or not (room.y0 <= cy <= room.y1):
                continue
            zones.append(rect_corners((cx + sign * depth / 2, cy), (depth, w), 0.0))
        else:
            sign = 1.0 if abs(cy - room.y0) < 1e-6 else -1.0
            if not (abs(cy - room.y0) < 1e-6 or abs(cy - room.y1) < 1e-6) or not (room.x0 <= cx <= room.x1):
                continue
            zones.append(rect_corners((cx, cy + sign * depth / 2), (w, depth), 0.0))
    return zones


class RoomFiller:
    """Places models in one room (inner rectangle ``inner``) against the objects already placed."""

    def __init__(self, rng: np.random.Generator, inner: Rect, room: int, zones: list[np.ndarray],
                 placed: list[Placed]) -> None:
        self.rng, self.inner, self.room, self.zones, self.placed = rng, inner, room, zones, placed

    def ok(self, cand: Placed, margin: float = 0.04) -> bool:
        c = cand.corners
        r = self.inner
        if c[:, 0].min() < r.x0 - 1e-6 or c[:, 0].max() > r.x1 + 1e-6 or c[:, 1].min() < r.y0 - 1e-6 \
                or c[:, 1].max() > r.y1 + 1e-6:
            return False
        if any(rects_overlap(c, z) for z in self.zones):
            return False
        # Pieces of other rooms lie beyond a wall (thicker than ``margin``): only this room's can overlap.
        return not any(p.room == self.room and rects_overlap(c, p.corners, margin) for p in self.placed)

    def _wall(self, cat: str, model: Model, corner: bool) -> Placed | None:
        w, d = model.size[0], model.size[1]
        r, gap = self.inner, 0.01
        for _ in range(30):
            side = ["south", "north", "west", "east"][int(self.rng.integers(4))]
            yaw = float(_WALL_YAW[side])
            length = r.w if side in ("south", "north") else r.h
            free = length - w
            if free < 0:
                continue
            t = (0.0 if self.rng.random() < 0.5 else free) if corner else float(self.rng.uniform(0, free))
            t += w / 2
            if side == "south":
                x, y = r.x0 + t, r.y0 + d / 2 + gap
            elif side == "north":
                x, y = r.x1 - t, r.y1 - d / 2 - gap
            elif side == "west":
                x, y = r.x0 + d / 2 + gap, r.y1 - t
            else:
                x, y = r.x1 - d / 2 - gap, r.y0 + t
            cand = Placed(cat, model, round(x, 3), round(y, 3), yaw, self.room)
            if self.ok(cand):
                return cand
        return None

    def _center(self, cat: str, model: Model) -> Placed | None:
        r = self.inner
        for _ in range(30):
            x = r.center[0] + float(self.rng.uniform(-0.25, 0.25)) * r.w
            y = r.center[1] + float(self.rng.uniform(-0.25, 0.25)) * r.h
            yaw = 0.0 if r.w >= r.h else np.pi / 2
            cand = Placed(cat, model, round(x, 3), round(y, 3), yaw + float(self.rng.integers(2)) * np.pi, self.room)
            if self.ok(cand, margin=0.45):  # leave walking space around free-standing pieces
                return cand
        return None

    def _anchored(self, cat: str, model: Model, rule: str, anchors: list[int]) -> Placed | None:
        kind = rule.split(":", 1)[0]
        w, d = model.size[0], model.size[1]
        for ai in self.rng.permutation(anchors):
            a = self.placed[int(ai)]
            aw, ad = a.model.size[0], a.model.size[1]
            cands: list[tuple[float, float, float]] = []  # local (x, y) in the anchor frame, relative yaw
            if kind == "front":
                dist = ad / 2 + d / 2 + (0.45 if cat == "coffee table" else 0.08)
                rel = 0.0 if cat == "coffee table" else np.pi
                if cat == "stool":
                    cands = [(float(x), dist, rel) for x in np.linspace(-aw / 2 + w, aw / 2 - w, 3)]
                else:
                    cands = [(0.0, dist, rel)]
            elif kind == "around":
                for s in (-1, 1):
                    n = max(1, int(aw // 0.6))
                    for k in range(n):
                        x = -aw / 2 + aw * (k + 0.5) / n
                        cands.append((x, s * (ad / 2 + d / 2 + 0.06), 0.0 if s < 0 else np.pi))
                cands += [(s * (aw / 2 + d / 2 + 0.06), 0.0, s * np.pi / 2) for s in (-1, 1)]
            elif kind == "beside":
                for s in (-1, 1):
                    cands.append((s * (aw / 2 + w / 2 + 0.04), -ad / 2 + d / 2, 0.0))
            elif kind == "near":
                for s in (-1, 1):
                    cands.append((s * (aw / 2 + d / 2 + 0.4), 0.0, s * np.pi / 2))
                    cands.append((s * (aw / 2 + d / 2 + 0.4), ad / 2, s * np.pi / 2))
                    cands.append((s * (aw / 2 + d / 2 + 0.4), -ad / 2, s * np.pi / 2))
                cands.append((0.0, ad / 2 + d / 2 + 0.45, np.pi))
            order = self.rng.permutation(len(cands))
            for k in order:
                lx, ly, rel = cands[int(k)]
                x, y = a.local_to_world(lx, ly)
                yaw = float(np.round(a.yaw + rel, 6))
                cand = Placed(cat, model, round(x, 3), round(y, 3), yaw, self.room, group=int(ai))
                if self.ok(cand, margin=0.02):
                    return cand
        return None

    def place(self, cat: str, model: Model, rule: str) -> Placed | None:
        """Place by ``rule``; pieces that can stand anywhere fall back to a free spot along a wall."""
        if rule in ("wall", "corner"):
            out = self._wall(cat, model, rule == "corner")
        elif rule == "center":
            out = self._center(cat, model)
        else:
            anchor_cat = rule.split(":", 1)[1]
            anchors = [i for i, p in enumerate(self.placed) if p.category == anchor_cat and p.room == self.room]
            out = self._anchored(cat, model, rule, anchors) if anchors else None
        if out is None and rule != "wall" and cat not in _ANCHORED_ONLY:
            out = self._wall(cat, model, False)
        return out
