"""Mapping quality against the simulator's truth (evaluation only: it reads the scene manifest and
the frames' ground-truth instance images; the mapping pipeline never does).

Each map object is matched to the ground-truth instance whose oriented box (grown by
``box_margin``) contains the largest share of its points, if that share is at least
``min_inside``. Then: precision = matched objects / objects; recall = instances seen in at least
``min_frames`` frames (``min_pixels`` visible pixels each) that got an object / such instances;
duplicate rate = objects beyond the first on the same instance / objects; category accuracy =
matched objects whose label is the instance's category / matched objects; centroid error = 3D
distance from the best (most hits) object's position to the instance's box centre; size error
(``size_error``) = the larger of its caption width and height errors; occupancy IoU
= IoU of OCCUPIED cells of the map and of the truth (sampled at the map's cell centres) over the
truth's apartment area.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import CapNavError
from capnav.core.frame import Frame
from capnav.core.grid import OCCUPIED, UNKNOWN, OccupancyGrid
from capnav.mapping.cmap import CapNavMap
from capnav.mapping.objects import MapObject
from capnav.sim.manifest import ObjectInstance, SceneManifest


@dataclass(frozen=True)
class QualityConfig:
    min_frames: int = 5
    min_pixels: int = 100
    min_inside: float = 0.5
    box_margin: float = 0.05


@dataclass
class MappingQuality:
    n_objects: int
    n_instances: int
    n_seen: int
    precision: float
    recall: float
    duplicate_rate: float
    category_accuracy: float
    median_centroid_error: float
    occupancy_iou: float | None
    per_instance: list[dict[str, Any]] = field(default_factory=list)
    unmatched_objects: list[dict[str, Any]] = field(default_factory=list)

    def rows(self) -> list[tuple[str, str, str]]:
        """(metric, value, target) rows for a table; targets are the project's acceptance levels for mapping."""
        iou = "n/a" if self.occupancy_iou is None else f"{self.occupancy_iou:.3f}"
        return [
            ("objects in map", str(self.n_objects), ""),
            ("instances (seen >= 5 frames)", f"{self.n_instances} ({self.n_seen})", ""),
            ("instance precision", f"{self.precision:.1%}", ""),
            ("instance recall (seen)", f"{self.recall:.1%}", ">= 95%"),
            ("duplicate rate", f"{self.duplicate_rate:.1%}", "<= 5%"),
            ("category accuracy", f"{self.category_accuracy:.1%}", ">= 90%"),
            ("median centroid error", f"{self.median_centroid_error * 100:.1f} cm", "<= 10 cm"),
            ("occupancy IoU", iou, ""),
        ]

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def visible_frames(frames: Iterable[Frame], min_pixels: int = 100) -> dict[int, int]:
    """Per ground-truth instance id: number of frames where at least ``min_pixels`` pixels show it."""
    counts: dict[int, int] = {}
    for f in frames:
        if f.gt_instance is None:
            continue
        ids, n = np.unique(f.gt_instance, return_counts=True)
        for i in ids[(n >= min_pixels) & (ids > 0)]:
            counts[int(i)] = counts.get(int(i), 0) + 1
    return counts


def inside_box(points: NDArray[np.floating], inst: ObjectInstance, margin: float) -> NDArray[np.bool_]:
    """Which points lie inside the instance's oriented box grown by ``margin``."""
    p = np.asarray(points, dtype=np.float64) - np.asarray(inst.center)
    c, s = np.cos(inst.yaw), np.sin(inst.yaw)
    local = np.stack([c * p[:, 0] + s * p[:, 1], -s * p[:, 0] + c * p[:, 1], p[:, 2]], axis=1)
    return np.all(np.abs(local) <= np.asarray(inst.size) / 2 + margin, axis=1)


def caption_size(extent: NDArray[np.floating]) -> tuple[float, float]:
    """(width, height) as captions state them: the larger horizontal side of the world-aligned
    extent (x, y, z) and its height."""
    e = np.asarray(extent, dtype=np.float64)
    return float(max(e[0], e[1])), float(e[2])


def true_extent(inst: ObjectInstance) -> NDArray[np.float64]:
    """World-aligned (x, y, z) extent of an instance's oriented box."""
    fp = np.asarray(inst.footprint, dtype=np.float64)
    return np.array([np.ptp(fp[:, 0]), np.ptp(fp[:, 1]), float(inst.size[2])])


def size_error(obj: MapObject, inst: ObjectInstance) -> float:
    """How far the caption's size of ``obj`` is from the truth: the larger of the width and the
    height errors (m), both measured as ``caption_size`` states them."""
    w, h = caption_size(obj.extent_max - obj.extent_min)
    tw, th = caption_size(true_extent(inst))
    return max(abs(w - tw), abs(h - th))


def occupancy_iou(pred: OccupancyGrid, truth: OccupancyGrid) -> float | None:
    """IoU of OCCUPIED cells over the map cells that fall on known truth cells."""
    rr, cc = np.mgrid[0:pred.spec.rows, 0:pred.spec.cols]
    xy = pred.spec.to_world(np.stack([rr.ravel(), cc.ravel()], axis=1))
    rc = truth.spec.to_cell(xy)
    ok = truth.spec.inside(rc)
    t = np.full(len(xy), UNKNOWN, dtype=np.uint8)
    t[ok] = truth.cells[rc[ok, 0], rc[ok, 1]]
    known = t != UNKNOWN
    a = (pred.cells.ravel() == OCCUPIED) & known
    b = (t == OCCUPIED) & known
    union = int((a | b).sum())
    return float((a & b).sum()) / union if union else None


def match_objects(objects: Sequence[MapObject], instances: Sequence[ObjectInstance],
                  config: QualityConfig | None = None) -> list[int | None]:
    """Per map object, the id of the instance whose box (grown by ``box_margin``) holds the largest
    share of its points, if that share is at least ``min_inside``; else None."""
    cfg = config or QualityConfig()
    out: list[int | None] = []
    for o in objects:
        shares = [float(inside_box(o.points, g, cfg.box_margin).mean()) for g in instances] if len(o.points) else []
        j = int(np.argmax(shares)) if shares else -1
        out.append(instances[j].id if j >= 0 and shares[j] >= cfg.min_inside else None)
    return out


def evaluate_map(cmap: CapNavMap, manifest: SceneManifest, seen: dict[int, int] | None = None,
                 truth_occupancy: OccupancyGrid | None = None, config: QualityConfig | None = None
                 ) -> MappingQuality:
    """Compare ``cmap`` with the truth. ``seen`` comes from ``visible_frames``; without it every
    instance counts as seen."""
    cfg = config or QualityConfig()
    insts = manifest.objects
    by_id = {g.id: g for g in insts}
    match: dict[int, list[int]] = {i.id: [] for i in insts}
    unmatched: list[dict[str, Any]] = []
    correct = matched = 0
    for k, (o, j) in enumerate(zip(cmap.objects, match_objects(cmap.objects, insts, cfg), strict=True)):
        if j is None:
            unmatched.append({"object": o.id, "label": o.label}
                             | ({"position": o.position.round(2).tolist()} if len(o.points) else {}))
            continue
        match[j].append(k)
        matched += 1
        correct += int(o.label == by_id[j].category)
    seen_ids = [i.id for i in insts if seen is None or seen.get(i.id, 0) >= cfg.min_frames]
    per: list[dict[str, Any]] = []
    errors: list[float] = []
    for g in insts:
        objs = [cmap.objects[k] for k in match[g.id]]
        rec: dict[str, Any] = {"instance": g.id, "category": g.category, "frames_seen": (seen or {}).get(g.id),
                               "objects": [o.id for o in objs]}
        if objs:
            best = max(objs, key=lambda o: o.hits)
            err = float(np.linalg.norm(best.position - np.asarray(g.center)))
            rec.update(label=best.label, centroid_error=round(err, 4), size_error=round(size_error(best, g), 4))
            errors.append(err)
        per.append(rec)
    n = len(cmap.objects)
    dups = sum(max(0, len(v) - 1) for v in match.values())
    recall = (sum(1 for i in seen_ids if match[i]) / len(seen_ids)) if seen_ids else 1.0
    return MappingQuality(
        n_objects=n, n_instances=len(insts), n_seen=len(seen_ids),
        precision=matched / n if n else 0.0, recall=recall, duplicate_rate=dups / n if n else 0.0,
        category_accuracy=correct / matched if matched else 0.0,
        median_centroid_error=float(np.median(errors)) if errors else float("nan"),
        occupancy_iou=occupancy_iou(cmap.occupancy, truth_occupancy) if truth_occupancy is not None else None,
        per_instance=per, unmatched_objects=unmatched,
    )


def truth_for_dataset(dataset: str | Path, manifest: SceneManifest, min_pixels: int = 100
                      ) -> tuple[dict[int, int] | None, OccupancyGrid | None, str]:
    """Evaluation truth beside a dataset: per-instance visible-frame counts from its truth images
    and the simulator's obstacle grid (rebuilt from the manifest's seed, used only if the rebuilt
    scene is the manifest's scene). Returns (counts or None, grid or None, a note on what is missing)."""
    notes: list[str] = []
    seen: dict[int, int] | None = None
    try:
        from capnav.io.dataset import DatasetReader

        reader = DatasetReader(dataset)
        if reader.has_gt:
            seen = visible_frames((reader.frame(i) for i in range(len(reader))), min_pixels)
        else:
            notes.append(f"{dataset} has no truth images: recall counts every instance as seen")
    except CapNavError as e:
        notes.append(f"no dataset frames ({e}): recall counts every instance as seen")
    occ: OccupancyGrid | None = None
    try:
        from capnav.sim.simulator import Simulator

        with Simulator.from_seed(manifest.seed) as sim:
            same = len(sim.manifest.objects) == len(manifest.objects) and all(
                np.allclose(a.center, b.center, atol=1e-6) for a, b in zip(sim.manifest.objects, manifest.objects,
                                                                           strict=True))
            if same:
                occ = sim.obstacles()
            else:
                notes.append("the scene rebuilt from the manifest's seed differs (non-default SimConfig?): "
                             "occupancy IoU not computed")
    except CapNavError as e:
        notes.append(f"occupancy IoU not computed: {e}")
    return seen, occ, "; ".join(notes)
