"""Small things standing on furniture (opt-in): cups, bottles, books, vases, bowls and laptops.

Real rooms have them on every table, counter and shelf, and a box detector's box around a table
then holds them too: lifted naively, their points join the table (its size grows, its label can
be outvoted). The default apartments have none (the benchmark's scenes stay as they were);
``FurnishConfig.surface_items`` turns them on, and each is recorded in the manifest with the id
of the object it stands on (``SceneManifest.items``).

Supporting surfaces come from the piece's primitive parts: the top face of any part at a height
a person puts things on, wide enough for a cup, with the room above it free of the piece's other
parts (a shelf under a shelf, books already there, a faucet). A Sweet Home 3D mesh is stretched
into the primitive's box, so for it only the top of that box is trusted. The kinds are COCO
classes the real detectors know (``capnav.perception.coco.KEPT_AS_IS``); their sizes are the
everyday ones (a mug ~8 cm across, a 13-inch laptop 31 x 22 cm).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from capnav.sim.apartment import Apartment, SceneObject
from capnav.sim.palette import COLORS
from capnav.sim.primitives import Model
from capnav.sim.shapes import Part, box, cyl, sphere

#: The kinds placed, all COCO classes.
ITEM_KINDS: tuple[str, ...] = ("cup", "bottle", "book", "vase", "bowl", "laptop")
#: Pieces things are put on (a bed, a chair or a stove is not a shelf).
SUPPORTS: tuple[str, ...] = ("table", "desk", "coffee table", "counter", "nightstand", "dresser", "cabinet",
                             "bookshelf")
#: Heights (m) of surfaces things are put on and a camera at 1.25 m sees.
SURFACE_HEIGHT = (0.3, 1.35)
_MIN_SIDE = 0.15
_ITEM_COLORS = ("white", "red", "blue", "green", "yellow", "black", "grey", "teal", "orange", "cream")


@dataclass
class SurfaceItem(SceneObject):
    """A small object on ``support`` (a furniture id), its base at height ``base`` (parts are baked
    at that height, so the world builds it like furniture)."""

    support: int = 0
    base: float = 0.0


def item_parts(kind: str, rng: np.random.Generator) -> list[Part]:
    """Parts of one ``kind`` in its local frame (origin at the footprint centre on its support)."""
    s = float(rng.uniform(0.9, 1.15))
    if kind == "cup":
        d, h = 0.08 * s, 0.1 * s
        return [cyl(0, 0, h / 2, d, h), box(d / 2 + 0.012, 0, h * 0.55, 0.024, 0.012, h * 0.55, "accent")]
    if kind == "bottle":
        d, h = 0.07 * s, 0.2 * s
        return [cyl(0, 0, h / 2, d, h), cyl(0, 0, h + 0.04 * s, 0.03 * s, 0.08 * s, "accent")]
    if kind == "book":
        w, dd, t = 0.16 * s, 0.23 * s, 0.035 * s
        return [box(0, 0, t / 2, w, dd, t, f"books:{int(rng.integers(8))}")]
    if kind == "vase":
        d, h = 0.12 * s, 0.26 * s
        return [cyl(0, 0, h * 0.35, d, h * 0.7), sphere(0, 0, h * 0.7, d * 0.9), cyl(0, 0, h * 0.9, d * 0.5, h * 0.2)]
    if kind == "bowl":
        d, h = 0.17 * s, 0.07 * s
        return [cyl(0, 0, h * 0.2, d * 0.5, h * 0.4, "accent"), cyl(0, 0, h * 0.7, d, h * 0.6)]
    if kind == "laptop":
        w, dd = 0.31 * s, 0.22 * s
        return [box(0, 0, 0.01, w, dd, 0.02, "dark"), box(0, -dd / 2 + 0.005, 0.02 + 0.1 * s, w, 0.01, 0.2 * s)]
    raise KeyError(kind)


def _extent(parts: list[Part]) -> tuple[np.ndarray, np.ndarray]:
    lo = np.min([np.subtract(p.center, np.divide(p.size, 2)) for p in parts], axis=0)
    hi = np.max([np.add(p.center, np.divide(p.size, 2)) for p in parts], axis=0)
    return lo, hi


def support_surfaces(o: SceneObject) -> list[tuple[float, np.ndarray, np.ndarray]]:
    """(height, local xy lo, local xy hi) of each top face things can stand on.

    A round top's face is the square inscribed in its circle; for a mesh only the box top."""
    parts = list(o.model.parts)
    top = max(p.center[2] + p.size[2] / 2 for p in parts)
    out = []
    for p in parts:
        z = p.center[2] + p.size[2] / 2
        if p.kind == "sphere" or (p.kind == "cylinder" and p.axis != "z"):
            continue
        if not SURFACE_HEIGHT[0] <= z <= SURFACE_HEIGHT[1] or (o.mesh is not None and z < top - 0.03):
            continue
        half = np.array(p.size[:2]) / 2 / (np.sqrt(2.0) if p.kind == "cylinder" else 1.0)
        if (2 * half < _MIN_SIDE).any():
            continue
        c = np.array(p.center[:2])
        out.append((float(z), c - half, c + half))
    return out


def _blocked(o: SceneObject, z: float, lo: np.ndarray, hi: np.ndarray, height: float) -> bool:
    """Whether any part of ``o`` (or an item already there) rises into the box above the surface."""
    for p in o.model.parts:
        plo = np.subtract(p.center, np.divide(p.size, 2))
        phi = np.add(p.center, np.divide(p.size, 2))
        if phi[2] <= z + 0.005 or plo[2] >= z + height:
            continue
        if (plo[:2] < hi).all() and (phi[:2] > lo).all():
            return True
    return False


def place_surface_items(apt: Apartment, counts: tuple[int, int], seed_offset: int = 17) -> list[SurfaceItem]:
    """Put ``counts`` (min, max) items on each supporting piece of ``apt``; sets ``apt.items`` and
    the manifest. Drawn from their own generator, so the furniture is the same with or without."""
    from capnav.sim.apartment import _manifest

    rng = np.random.default_rng([apt.seed, seed_offset])
    next_id = max((o.id for o in apt.objects), default=0) + 1
    items: list[SurfaceItem] = []
    for o in apt.objects:
        if o.category not in SUPPORTS:
            continue
        surfaces = support_surfaces(o)
        if not surfaces:
            continue
        taken: list[tuple[float, np.ndarray, np.ndarray, float]] = []  # (z, lo, hi, height) in o's frame
        for _ in range(int(rng.integers(counts[0], counts[1] + 1))):
            kind = ITEM_KINDS[int(rng.integers(len(ITEM_KINDS)))]
            parts = item_parts(kind, rng)
            ilo, ihi = _extent(parts)
            turn = float(rng.integers(4)) * np.pi / 2
            cs, sn = round(np.cos(turn)), round(np.sin(turn))
            size2 = np.abs(np.array([[cs, -sn], [sn, cs]]) @ (ihi[:2] - ilo[:2]))
            for _try in range(20):
                z, slo, shi = surfaces[int(rng.integers(len(surfaces)))]
                room = shi - slo - size2 - 0.04
                if (room < 0).any():
                    continue
                c = slo + 0.02 + size2 / 2 + rng.random(2) * room
                lo, hi = c - size2 / 2, c + size2 / 2
                h = float(ihi[2])
                if _blocked(o, z, lo - 0.01, hi + 0.01, h):
                    continue
                if any(abs(tz - z) < 0.01 and (tlo < hi + 0.02).all() and (thi > lo - 0.02).all()
                       for tz, tlo, thi, _ in taken):
                    continue
                taken.append((z, lo, hi, h))
                x, y = (float(v) for v in _to_world(o, c))
                yaw = float(o.yaw + turn)
                centre = (ilo[:2] + ihi[:2]) / 2
                baked = [Part(p.kind, (p.center[0] - centre[0], p.center[1] - centre[1], p.center[2] + z), p.size,
                              p.role, p.axis) for p in parts]
                model = Model(kind, (round(float(ihi[0] - ilo[0]), 4), round(float(ihi[1] - ilo[1]), 4),
                                     round(h, 4)), tuple(baked))
                name = _ITEM_COLORS[int(rng.integers(len(_ITEM_COLORS)))]
                roles = {"main": COLORS[name], "accent": COLORS["white"] if name != "white" else COLORS["grey"],
                         "dark": COLORS["dark grey"]}
                items.append(SurfaceItem(next_id, kind, model, round(x, 4), round(y, 4), yaw, o.room, name,
                                         "plastic", roles, support=o.id, base=round(z, 4)))
                next_id += 1
                break
    apt.items = list(items)
    apt.manifest = _manifest(apt)
    return items


def _to_world(o: SceneObject, local: np.ndarray) -> np.ndarray:
    c, s = np.cos(o.yaw), np.sin(o.yaw)
    return np.array([o.x + c * local[0] - s * local[1], o.y + s * local[0] + c * local[1]])
