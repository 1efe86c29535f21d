"""The top-down navigation picture (like the paper's Figure 5) and the same content as JSON.

Occupancy in grey levels, every mapped object as its footprint with a short label, the chosen one
highlighted, the planned path dashed, the executed trajectory solid, start and end marked.
Drawn with matplotlib's Agg canvas directly (no pyplot state), so it is safe in threads and CI.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.atomic import atomic_path, write_json
from capnav.core.grid import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from capnav.mapping.objects import MapObject

#: Grey levels of the occupancy image: free white, unknown light grey, occupied dark.
OCC_RGB = {FREE: (1.0, 1.0, 1.0), UNKNOWN: (0.82, 0.82, 0.85), OCCUPIED: (0.45, 0.45, 0.48)}
CHOSEN = "#d62728"
PATH = "#1f77b4"
TRAJ = "#ff7f0e"

Pose = Sequence[float] | NDArray[np.floating]


def short_label(obj: MapObject, width: int = 12) -> str:
    """``"7 coffee tab."``: the id and the category, cut to ``width`` characters."""
    name = obj.label if len(obj.label) <= width else obj.label[: width - 1] + "."
    return f"{obj.id} {name}"


#: Objects at least this tall (m) are hatched and labelled with their height: seen from the side
#: only (a wardrobe, a fridge), their tops are never observed, and a picture from above would
#: otherwise not tell them from a low box.
TALL_M = 1.5
#: A footprint hull filling less than this share of its smallest enclosing rectangle is drawn as the
#: rectangle: a box seen from one corner shows two faces, whose hull is a triangle.
BOX_FILL = 0.7


def object_height(obj: MapObject) -> float:
    """Metres from the lowest to the highest observed point."""
    return float(obj.extent_max[2] - obj.extent_min[2])


def min_area_rectangle(pts: NDArray[np.float64]) -> NDArray[np.float64]:
    """The 4 corners of the smallest rectangle enclosing the convex polygon ``pts`` (rotating calipers:
    one side of it lies on an edge of the hull). Of rectangles within 15% of the smallest, the one
    whose sides carry most of the hull's perimeter: a box seen from a corner has a triangular hull of
    equal-area rectangles on its two seen faces and on the unseen diagonal, and the faces are what
    was observed."""
    edges = np.diff(np.vstack([pts, pts[:1]]), axis=0)
    lengths = np.hypot(edges[:, 0], edges[:, 1])
    dirs = np.mod(np.arctan2(edges[:, 1], edges[:, 0]), np.pi / 2)
    cands = []
    for a in np.unique(np.round(dirs, 6)):
        rot = np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]])
        q = pts @ rot.T
        lo, hi = q.min(axis=0), q.max(axis=0)
        gap = np.abs((dirs - a + np.pi / 4) % (np.pi / 2) - np.pi / 4)  # edge angle to the sides, mod 90 deg
        on_sides = float(lengths[gap < np.radians(10.0)].sum())
        corners = np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])
        cands.append((float(np.prod(hi - lo)), on_sides, corners @ rot))
    smallest = min(c[0] for c in cands)
    return max((c for c in cands if c[0] <= 1.15 * smallest), key=lambda c: c[1])[2]


def _polygon_area(p: NDArray[np.float64]) -> float:
    x, y = p[:, 0], p[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def drawn_footprint(obj: MapObject) -> NDArray[np.float64] | None:
    """The polygon drawn for an object: its footprint hull, or the hull's smallest rectangle when the
    hull is a box seen from a corner (``BOX_FILL``); None when there is no footprint."""
    fp = np.asarray(obj.footprint, dtype=np.float64)
    if fp.ndim != 2 or len(fp) < 3:
        return None
    rect = min_area_rectangle(fp)
    area = _polygon_area(rect)
    return rect if area > 0 and _polygon_area(fp) < BOX_FILL * area else fp


def occupancy_rgb(occ: OccupancyGrid) -> NDArray[np.float64]:
    lut = np.zeros((256, 3))
    for value, rgb in OCC_RGB.items():
        lut[value] = rgb
    return lut[occ.cells]


def draw_navigation(occ: OccupancyGrid, objects: Sequence[MapObject], chosen_id: int | None,
                    path_xy: NDArray[np.floating] | None, trajectory_xy: NDArray[np.floating] | None,
                    start: Pose | None, end: Pose | None, title: str, out_png: str | Path,
                    goal: Pose | None = None, reach: float | None = None, dpi: int = 120,
                    abandoned: Sequence[NDArray[np.floating]] = (),
                    camera_xy: NDArray[np.floating] | None = None) -> Path:
    """Draw the picture and write it atomically to ``out_png``; returns the path.

    ``start`` / ``end`` / ``goal`` are (x, y) or (x, y, yaw): with a yaw an arrow shows the heading.
    ``reach`` draws the success radius around the chosen object's footprint; ``abandoned`` are
    earlier plans given up after a collision (thin dotted), so replanning is visible; ``camera_xy``
    the path of the camera that recorded the map (thin grey).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.patches import Polygon

    s = occ.spec
    extent = (s.x0, s.x0 + s.cols * s.resolution, s.y0, s.y0 + s.rows * s.resolution)
    w_m, h_m = extent[1] - extent[0], extent[3] - extent[2]
    fig_w = 7.5  # of which about 6 inches are map, the rest the legend
    fig = Figure(figsize=(fig_w + 1.5, max(3.0, min(12.0, fig_w * h_m / max(w_m, 1e-6) + 0.9))), dpi=dpi)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    ax.imshow(occupancy_rgb(occ), origin="lower", extent=extent, interpolation="nearest")
    for obj in objects:
        fp = drawn_footprint(obj)
        if fp is None:
            continue
        chosen = obj.id == chosen_id
        tall = object_height(obj) >= TALL_M
        ax.add_patch(Polygon(fp, closed=True, fill=True, alpha=0.6 if chosen else 0.5,
                             facecolor=CHOSEN if chosen else "#7cc47f", hatch="////" if tall else None,
                             edgecolor=CHOSEN if chosen else "#1b5e20", linewidth=2.2 if chosen else 0.8))
        cx, cy = fp.mean(axis=0)
        label = short_label(obj) + (f"\n{object_height(obj):.1f} m tall" if tall else "")
        ax.text(cx, cy, label, fontsize=7.5 if chosen else 5.5, ha="center", va="center",
                color=CHOSEN if chosen else "#1b3d1b", fontweight="bold" if chosen else "normal",
                bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.7})
        if chosen and reach:
            _draw_reach(ax, fp, reach)
    for k, a in enumerate(abandoned):
        q = np.asarray(a, dtype=np.float64)
        if len(q):
            ax.plot(q[:, 0], q[:, 1], ":", color="#7f7f7f", lw=1.1, zorder=4,
                    label="abandoned plan" if k == 0 else None)
    if camera_xy is not None and len(camera_xy):
        c = np.asarray(camera_xy, dtype=np.float64)
        ax.plot(c[:, 0], c[:, 1], "-", color="#8c8c8c", lw=1.0, label="camera path", zorder=3)
    if path_xy is not None and len(path_xy):
        p = np.asarray(path_xy, dtype=np.float64)
        ax.plot(p[:, 0], p[:, 1], "--", color=PATH, lw=1.4, label="planned path", zorder=6)
        ax.plot(p[:, 0], p[:, 1], ".", color=PATH, ms=4, zorder=6)
    if trajectory_xy is not None and len(trajectory_xy):
        t = np.asarray(trajectory_xy, dtype=np.float64)
        ax.plot(t[:, 0], t[:, 1], "-", color=TRAJ, lw=2.6, alpha=0.9, label="executed", zorder=5)
    _mark(ax, start, "o", "#2ca02c", "start")
    _mark(ax, goal, "X", PATH, "goal")
    _mark(ax, end, "s", CHOSEN, "end")
    ax.set_xlim(extent[0], extent[1])
    ax.set_ylim(extent[2], extent[3])
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title, fontsize=9, wrap=True)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7, framealpha=0.85, borderaxespad=0.0)
    fig.tight_layout()
    out = Path(out_png)
    with atomic_path(out, suffix=".png") as tmp:
        fig.savefig(tmp, format="png")
    return out


def _mark(ax: Any, pose: Pose | None, marker: str, color: str, label: str) -> None:
    if pose is None:
        return
    p = [float(v) for v in pose]
    ax.plot(p[0], p[1], marker, color=color, ms=9, mec="black", mew=0.8, label=label, zorder=7)
    if len(p) >= 3:
        ax.annotate("", xy=(p[0] + 0.45 * np.cos(p[2]), p[1] + 0.45 * np.sin(p[2])), xytext=(p[0], p[1]),
                    arrowprops={"arrowstyle": "->", "color": color, "lw": 1.5}, zorder=7)


def _draw_reach(ax: Any, fp: NDArray[np.float64], reach: float) -> None:
    """The set of points within ``reach`` of the footprint, as a contour line."""
    lo, hi = fp.min(axis=0) - reach - 0.1, fp.max(axis=0) + reach + 0.1
    xs, ys = np.linspace(lo[0], hi[0], 120), np.linspace(lo[1], hi[1], 120)
    gx, gy = np.meshgrid(xs, ys)
    from capnav.core.footprint import footprint_distance

    d = footprint_distance(np.stack([gx.ravel(), gy.ravel()], axis=1), fp).reshape(gx.shape)
    ax.contour(gx, gy, d, levels=[reach], colors=[CHOSEN], linewidths=0.9, linestyles=":")


def navigation_record(occ: OccupancyGrid, objects: Sequence[MapObject], chosen_id: int | None,
                      path_xy: NDArray[np.floating] | None, trajectory_xy: NDArray[np.floating] | None,
                      start: Pose | None, end: Pose | None, title: str, **extra: Any) -> dict[str, Any]:
    """The picture's content as plain data (for the JSON beside the PNG)."""

    def pts(a: Any) -> list[list[float]]:
        return [] if a is None else np.round(np.asarray(a, dtype=np.float64), 4).tolist()

    return {
        "title": title,
        "grid": occ.spec.to_dict(),
        "occupancy_counts": {name: int((occ.cells == v).sum())
                             for name, v in (("free", FREE), ("occupied", OCCUPIED), ("unknown", UNKNOWN))},
        "objects": [{"id": o.id, "label": o.label, "short_label": short_label(o), "chosen": o.id == chosen_id,
                     "xy": pts(o.xy), "footprint": pts(o.footprint), "caption": o.caption} for o in objects],
        "chosen_id": chosen_id,
        "path": pts(path_xy),
        "trajectory": pts(trajectory_xy),
        "start": None if start is None else [round(float(v), 4) for v in start],
        "end": None if end is None else [round(float(v), 4) for v in end],
        **extra,
    }


def write_navigation(out_dir: str | Path, stem: str, occ: OccupancyGrid, objects: Sequence[MapObject],
                     chosen_id: int | None, path_xy: NDArray[np.floating] | None,
                     trajectory_xy: NDArray[np.floating] | None, start: Pose | None, end: Pose | None,
                     title: str, goal: Pose | None = None, reach: float | None = None,
                     abandoned: Sequence[NDArray[np.floating]] = (), **extra: Any) -> tuple[Path, Path]:
    """Both files: ``<stem>.png`` and ``<stem>.json`` in ``out_dir``."""
    out = Path(out_dir)
    png = draw_navigation(occ, objects, chosen_id, path_xy, trajectory_xy, start, end, title, out / f"{stem}.png",
                          goal=goal, reach=reach, abandoned=abandoned)
    rec = navigation_record(occ, objects, chosen_id, path_xy, trajectory_xy, start, end, title,
                            goal=None if goal is None else [round(float(v), 4) for v in goal], **extra)
    js = out / f"{stem}.json"
    write_json(js, rec)
    return png, js
