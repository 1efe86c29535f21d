"""Shape words from an object's fused points: its outline and a plant's growth; None when unsure.

Why: people single objects out by shape ("the round ottoman", "the L-shaped couch", "the leafy
plant", "the cactus"), and the map holds each object's points. Every rule here reads only those points
(world frame, z up); its thresholds are measured by ``benchmarks/measure_evidence.py`` against
the simulator's shape variants and listed in docs/benchmarks.md. A word is said only when its
measure is clearly on one side; a verifier refuses only a word that contradicts a said one.

Not said: whether a sofa's arms are rolled ("curved") or boxed. The fall of the arm tops towards
their outer side was tried during development: most rolled arms fell no further than box arms,
and a box arm sampled like the map samples it (3 cm voxels, 1 cm noise) seemed to fall as far,
so neither word is said (no figure: the measure is not kept in the repository).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]

#: Spoken shape word -> observed words that contradict it, kept only where the observed word was
#: never wrong on the measured apartments (benchmarks/measure_evidence.py): "rectangular" was never
#: said of a round table, stool or ottoman, but "round" was of 2 of 10 square ones, so "the square
#: stool" is not refused for a footprint measured round, only ranked below.
CONFLICTS: dict[str, frozenset[str]] = {
    "round": frozenset({"rectangular", "long", "L-shaped"}),
    "square": frozenset({"long", "L-shaped"}),
    "long": frozenset({"round"}),
    "L-shaped": frozenset({"round"}),
    "leafy": frozenset({"slender"}),
    "slender": frozenset({"leafy"}),
}


@dataclass(frozen=True)
class FormConfig:
    round_circularity: float = 0.86  # 4*pi*A/P^2 of the footprint hull (square: 0.785, circle: 1)
    round_aspect: float = 1.25
    rect_fill: float = 0.9  # hull area / its minimum-area rectangle at or above which it is rectangular
    rect_circularity: float = 0.82  # ... and circularity below this (a disc fills 0.785)
    l_shape_fill: float = 0.86  # occupied share of the footprint hull below which it is L-shaped
    l_shape_min_area: float = 1.5  # m² of hull: only sofa/counter-sized objects can be L-shaped
    long_aspect: float = 2.3
    #: Plants: width of the upper 60% (foliage) over the lowest 20% (pot); leafy foliage spreads
    #: wider than its pot, a columnar one (a cactus) stays narrower. Leafy crowns on a stem and
    #: leafy bushes measure alike (1.20-1.63 on seeds 1-3), so both are "leafy", never "bushy": the
    #: points do not tell a bush from a crown on a stem.
    leafy_spread: float = 1.15
    slender_spread: float = 0.8


def _hull(xy: F64) -> tuple[float, float, F64, F64] | None:
    """(area, perimeter, vertices, facet equations) of the 2D convex hull."""
    from scipy.spatial import ConvexHull, QhullError

    try:
        hull = ConvexHull(xy)
    except (QhullError, ValueError):
        return None
    return float(hull.volume), float(hull.area), xy[hull.vertices], np.asarray(hull.equations)


def min_rect_fill(hull_pts: F64, area: float) -> float:
    """Hull area over the area of its minimum-area enclosing rectangle (rotating calipers)."""
    best = np.inf
    for i in range(len(hull_pts)):
        e = hull_pts[(i + 1) % len(hull_pts)] - hull_pts[i]
        n = float(np.hypot(*e))
        if n < 1e-9:
            continue
        e = e / n
        f = np.array([-e[1], e[0]])
        best = min(best, float(np.ptp(hull_pts @ e) * np.ptp(hull_pts @ f)))
    return area / best if np.isfinite(best) and best > 0 else 0.0


def outline(points: F64, cfg: FormConfig | None = None) -> str | None:
    """"L-shaped", "round", "long" or "rectangular" from the top-down point footprint, else None."""
    cfg = cfg or FormConfig()
    pts = np.asarray(points, dtype=np.float64)
    if len(pts) < 40:
        return None
    xy = pts[:, :2]
    h = _hull(xy)
    if h is None:
        return None
    area, perim, hull_pts, eq = h
    if area < 0.02:
        return None
    # Occupied share of the hull, both counted on the same grid (cells whose centre is inside).
    res = max(0.04, np.sqrt(area / 400.0))
    origin = xy.min(0)
    cells = np.unique(np.floor((xy - origin) / res).astype(np.int64), axis=0)
    span = np.floor((xy.max(0) - origin) / res).astype(np.int64) + 1
    gx, gy = np.meshgrid(np.arange(span[0]), np.arange(span[1]), indexing="ij")
    centres = origin + (np.stack([gx.ravel(), gy.ravel()], 1) + 0.5) * res
    in_hull = int(np.all(centres @ eq[:, :2].T + eq[:, 2] <= 1e-9, axis=1).sum())  # inside: n . p + d <= 0
    occ = len(cells) / max(in_hull, 1)
    ev = np.linalg.eigvalsh(np.cov((xy - xy.mean(0)).T))
    aspect = float(np.sqrt(max(ev[1], 1e-9) / max(ev[0], 1e-9)))
    circ = 4 * np.pi * area / perim**2
    if occ < cfg.l_shape_fill and aspect < 2.0 and area >= cfg.l_shape_min_area:
        return "L-shaped"
    if circ >= cfg.round_circularity and aspect < cfg.round_aspect:
        return "round"
    if aspect >= cfg.long_aspect:
        return "long"
    if min_rect_fill(hull_pts, area) >= cfg.rect_fill and circ < cfg.rect_circularity:
        return "rectangular"
    return None


def foliage_spread(points: F64) -> float | None:
    """90th-percentile radial width of the upper 60% of a plant over that of its lowest 20%."""
    p = np.asarray(points, dtype=np.float64)
    if len(p) < 60:
        return None
    z = p[:, 2]
    lo, hi = float(z.min()), float(z.max())
    if hi - lo < 0.2:
        return None

    def width(sel: NDArray[np.bool_]) -> float:
        s = p[sel, :2]
        return float(2 * np.quantile(np.hypot(*(s - np.median(s, 0)).T), 0.9)) if len(s) >= 8 else 0.0

    pot = width(z <= lo + 0.2 * (hi - lo))
    leaves = width(z >= lo + 0.4 * (hi - lo))
    return leaves / pot if pot > 0.02 and leaves > 0 else None


def growth(points: F64, cfg: FormConfig | None = None) -> str | None:
    """"leafy" (foliage wider than its pot) or "slender" (narrower: columnar, like a cactus)."""
    cfg = cfg or FormConfig()
    s = foliage_spread(points)
    if s is None:
        return None
    if s >= cfg.leafy_spread:
        return "leafy"
    if s <= cfg.slender_spread:
        return "slender"
    return None


def shape_conflict(spoken: str, observed: list[str]) -> str | None:
    """The observed word that contradicts a spoken shape word, if any."""
    bad = CONFLICTS.get(spoken, frozenset())
    return next((w for w in observed if w in bad), None)
