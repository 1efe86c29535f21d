"""Small things on surfaces, scored against the manifest (evaluation only: reads the truth).

A scene made with ``capnav sim --surface-items`` records each cup, book or laptop with the
object it stands on (``SceneManifest.items``). Per item kind: recall (items seen in at least
``min_frames`` frames with a map object on them), duplicates, size error, and how often the
support *absorbed* the item: the map object of its table or counter holds points inside the
item's box, above the support's top. Per support: how often its label went to a thing standing
on it (``outvoted``). A map object belongs to an item when at least ``min_inside`` of its points
lie in the item's box (grown by ``item_margin``), else to the piece of furniture holding most of
them (``map_quality.evaluate_map``'s rule), so a table that swallowed a cup is still the table.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass
from typing import Any

import numpy as np

from capnav.core.categories import BY_NAME
from capnav.eval.map_quality import QualityConfig, caption_size, inside_box, true_extent
from capnav.mapping.cmap import CapNavMap
from capnav.sim.manifest import ItemInstance, ObjectInstance, SceneManifest


@dataclass(frozen=True)
class SurfaceQualityConfig:
    item_margin: float = 0.03
    absorbed_points: int = 5  # points of the support's object inside the item (above the top)
    above_top: float = 0.03  # above the support's top: a laptop's 2 cm keyboard is the top to a depth sensor


def relative_size_error(extent: Any, inst: ObjectInstance | ItemInstance) -> float:
    """The larger of the caption width and height errors, each relative to the truth."""
    w, h = caption_size(np.asarray(extent))
    tw, th = caption_size(true_extent(inst))  # type: ignore[arg-type]
    return max(abs(w - tw) / max(tw, 1e-6), abs(h - th) / max(th, 1e-6))


def assign(cmap: CapNavMap, manifest: SceneManifest, qc: QualityConfig | None = None,
           sc: SurfaceQualityConfig | None = None) -> dict[int, int]:
    """Map object index -> instance id (item or object) it lies on; unmatched objects are absent."""
    qc = qc or QualityConfig()
    sc = sc or SurfaceQualityConfig()
    items = manifest.items or []
    out: dict[int, int] = {}
    for k, o in enumerate(cmap.objects):
        if len(o.points) == 0:
            continue
        ishare = [float(inside_box(o.points, it, sc.item_margin).mean()) for it in items]  # type: ignore[arg-type]
        if ishare and max(ishare) >= qc.min_inside:
            out[k] = items[int(np.argmax(ishare))].id
            continue
        shares = [float(inside_box(o.points, g, qc.box_margin).mean()) for g in manifest.objects]
        if shares and max(shares) >= qc.min_inside:
            out[k] = manifest.objects[int(np.argmax(shares))].id
    return out


def surface_report(cmap: CapNavMap, manifest: SceneManifest, seen: dict[int, int] | None,
                   qc: QualityConfig | None = None, sc: SurfaceQualityConfig | None = None
                   ) -> dict[str, dict[str, Any]]:
    """Counts per item kind (``seen``, ``found``, ``on``, ``dups``, ``absorbed``, ``size_errors``)
    and per support category (``supports``, ``outvoted``), keyed ``item:<kind>`` / ``support:<cat>``."""
    qc = qc or QualityConfig()
    sc = sc or SurfaceQualityConfig()
    owner = assign(cmap, manifest, qc, sc)
    by_inst: dict[int, list[int]] = defaultdict(list)
    for k, iid in owner.items():
        by_inst[iid].append(k)
    kinds = {it.category for it in manifest.items or []}
    out: dict[str, dict[str, Any]] = {f"item:{c}": {"seen": 0, "found": 0, "on": 0, "dups": 0, "absorbed": 0,
                                                    "size_errors": []} for c in sorted(kinds)}
    supports: set[int] = set()
    for it in manifest.items or []:
        if (seen or {}).get(it.id, 0) < qc.min_frames and seen is not None:
            continue
        rec = out[f"item:{it.category}"]
        rec["seen"] += 1
        objs = by_inst.get(it.id, [])
        rec["found"] += bool(objs)
        rec["on"] += len(objs)
        rec["dups"] += max(0, len(objs) - 1)
        if objs:
            best = max(objs, key=lambda k: cmap.objects[k].hits)
            o = cmap.objects[best]
            rec["size_errors"].append(relative_size_error(o.extent_max - o.extent_min, it))
        base = it.center[2] - it.size[2] / 2
        for k in by_inst.get(it.support, []):
            p = cmap.objects[k].points
            n = int((inside_box(p, it, 0.01) & (p[:, 2] >= base + sc.above_top)).sum())  # type: ignore[arg-type]
            if n >= sc.absorbed_points:
                rec["absorbed"] += 1
                break
        supports.add(it.support)
    for sid in sorted(supports):
        sup = manifest.object(sid)
        rec = out.setdefault(f"support:{sup.category}", {"supports": 0, "mapped": 0, "outvoted": 0})
        rec["supports"] += 1
        objs = by_inst.get(sid, [])
        if objs:
            rec["mapped"] += 1
            best = max(objs, key=lambda k: cmap.objects[k].hits)
            rec["outvoted"] += cmap.objects[best].label not in BY_NAME  # a cup's or a book's label
    return out
