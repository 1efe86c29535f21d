"""Furniture sources: built-in primitives (default) or Sweet Home 3D meshes, chosen by name.

A source turns the placed primitive models of an apartment into what gets drawn. The placement,
footprints, collision and reachability are decided on the primitive models first; a mesh source
then draws a catalog model of the same category stretched into the same box (as Sweet Home 3D
itself does), preferring models whose proportions match, so every guarantee still holds.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from capnav.core.registry import Registry
from capnav.sim.apartment import Apartment, _manifest
from capnav.sim.config import SimConfig
from capnav.sim.palette import COLORS

FurnitureSource = Callable[[Apartment, SimConfig], Apartment]
FURNITURE: Registry[Apartment] = Registry("furniture source")


def furnish(apt: Apartment, config: SimConfig) -> Apartment:
    """Apply ``config.furniture`` (a FURNITURE registry name) to a generated apartment, then put
    the opt-in small things on its surfaces (``FurnishConfig.surface_items``)."""
    apt = FURNITURE.create(config.furniture, apt=apt, config=config)
    if config.furnish.surface_items[1] > 0:
        from capnav.sim.surface_items import place_surface_items

        place_surface_items(apt, config.furnish.surface_items)
    return apt


@FURNITURE.register("primitives")
def _primitives(apt: Apartment, config: SimConfig) -> Apartment:
    return apt


def _nearest_color(rgb: np.ndarray) -> str:
    names = list(COLORS)
    ref = np.array([COLORS[n] for n in names], dtype=np.float64)
    return names[int(np.argmin(np.linalg.norm(ref - rgb[None, :], axis=1)))]


@FURNITURE.register("sh3d")
def _sh3d(apt: Apartment, config: SimConfig) -> Apartment:
    from capnav.sim.sh3d import load_catalog

    catalog = load_catalog(Path(config.assets_dir) if config.assets_dir else None)
    by_cat: dict[str, list] = {}  # type: ignore[type-arg]
    for m in catalog:
        by_cat.setdefault(m.category, []).append(m)
    rng = np.random.default_rng([apt.seed, 11])
    for o in apt.objects:
        cands = by_cat.get(o.category)
        if not cands:
            continue  # no mesh of this category: keep the primitive
        want = np.log(np.asarray(o.model.size))
        cost = [float(np.abs(np.log(np.asarray(m.size)) - want).sum()) for m in cands]
        order = np.argsort(cost, kind="stable")[:3]  # the three best-proportioned, for variety
        m = cands[int(order[int(rng.integers(len(order)))])]
        o.mesh, o.source, o.license = m, "sh3d", m.license
        areas = np.array([a for _, _, a in m.parts]) + 1e-9
        rgb = np.array([c[:3] for _, c, _ in m.parts]) * 255.0
        dominant = rgb[int(np.argmax(areas))]
        o.color_name = _nearest_color(dominant)
        o.roles = {**o.roles, "main": (int(dominant[0]), int(dominant[1]), int(dominant[2]))}
        o.material = "mesh"
    apt.manifest = _manifest(apt)
    return apt
