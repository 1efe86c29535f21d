"""Top-down picture of a simulated apartment: rooms, walls with door gaps, objects labelled."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from capnav.core.atomic import atomic_path
from capnav.core.frame import Frame
from capnav.core.grid import FREE, OccupancyGrid
from capnav.sim.manifest import SceneManifest

_ROOM_TINT = {"living room": "#f3ead8", "kitchen": "#e3eef3", "bedroom": "#efe3ef", "bathroom": "#dff0ea",
              "office": "#eef0dc", "hallway": "#ececec"}


def draw_scene(manifest: SceneManifest, path: str | Path, navigable: OccupancyGrid | None = None,
               trajectory: NDArray[np.floating] | None = None, title: str | None = None, dpi: int = 110,
               id_prefix: str = "") -> Path:
    """Save a labelled top-down map (PNG). ``navigable`` shades where the agent fits; ``trajectory``
    (K, 2+) draws a path. North (+y) is up. Objects are labelled with their truth ids, written
    ``{id_prefix}{id}``: a picture shown beside map pictures marks them (e.g. "T5") so that they
    are never read as map ids."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon

    x0, y0, x1, y1 = manifest.bounds
    w, h = x1 - x0, y1 - y0
    fig, ax = plt.subplots(figsize=(min(14.0, 1.0 + w * 0.9), min(12.0, 1.0 + h * 0.9)))
    for room in manifest.rooms:
        poly = np.asarray(room.polygon)
        ax.add_patch(Polygon(poly, closed=True, facecolor=_ROOM_TINT.get(room.name, "#eeeeee"), edgecolor="none"))
        cx = float(poly[:, 0].mean())
        ax.text(cx, poly[:, 1].max() - 0.25, f"{room.name} ({room.id})", ha="center", va="top", fontsize=8,
                color="#555555", style="italic")
    if navigable is not None:
        from matplotlib.colors import ListedColormap

        free = np.ma.masked_where(navigable.cells != FREE, np.ones(navigable.cells.shape))
        s = navigable.spec
        ax.imshow(free, origin="lower", extent=(s.x0, s.x0 + s.cols * s.resolution, s.y0, s.y0 + s.rows * s.resolution),
                  cmap=ListedColormap(["#6cc46c"]), alpha=0.35, interpolation="nearest", zorder=1.5)
    for room in manifest.rooms:  # walls
        poly = np.asarray(room.polygon + room.polygon[:1])
        ax.plot(poly[:, 0], poly[:, 1], color="#333333", lw=2.5, solid_capstyle="butt")
    for door in manifest.doors:
        a, b = _door_ends(door.center, door.width, manifest)
        ax.plot([a[0], b[0]], [a[1], b[1]], color="white", lw=4.0, solid_capstyle="butt")
    for o in manifest.objects:
        fp = np.asarray(o.footprint)
        ax.add_patch(Polygon(fp, closed=True, facecolor=np.asarray(o.color_rgb) / 255.0, edgecolor="black",
                             lw=0.6, alpha=0.9))
        ax.text(o.center[0], o.center[1], f"{id_prefix}{o.id} {o.category}", ha="center", va="center", fontsize=6,
                bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.7})
    if trajectory is not None and len(trajectory) > 0:
        t = np.asarray(trajectory)
        ax.plot(t[:, 0], t[:, 1], color="#d62728", lw=1.0, alpha=0.8)
        ax.plot(t[0, 0], t[0, 1], "o", color="#d62728", ms=4)
    ax.set_xlim(x0 - 0.2, x1 + 0.2)
    ax.set_ylim(y0 - 0.2, y1 + 0.2)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title or f"apartment seed {manifest.seed}: {len(manifest.rooms)} rooms, "
                 f"{len(manifest.objects)} objects", fontsize=10)
    fig.tight_layout()
    out = Path(path)
    with atomic_path(out, suffix=".png") as tmp:
        fig.savefig(tmp, dpi=dpi, format="png")
    plt.close(fig)
    return out


def _ids_to_rgb(ids: NDArray[np.integer]) -> NDArray[np.uint8]:
    """Distinct stable colours per id (0 = black)."""
    ids = np.asarray(ids, dtype=np.int64)
    rgb = np.stack([(ids * 97) % 200 + 55, (ids * 57) % 200 + 55, (ids * 151) % 200 + 55], axis=-1)
    rgb[ids == 0] = 0
    return rgb.astype(np.uint8)


def frame_grid(frames: list[Frame], path: str | Path, cols: int = 4, truth: bool = False,
               max_depth: float = 6.0) -> Path:
    """Save frames side by side (PNG). With ``truth`` each row is rgb | depth | instance | category."""
    from PIL import Image

    tiles: list[NDArray[np.uint8]] = []
    for f in frames:
        if not truth:
            tiles.append(f.rgb)
            continue
        d = np.clip(np.nan_to_num(f.depth) / max_depth, 0, 1)
        depth = (np.stack([d, d, d], -1) * 255).astype(np.uint8)
        depth[f.depth <= 0] = (255, 0, 255)
        inst = _ids_to_rgb(f.gt_instance if f.gt_instance is not None else np.zeros(f.shape, int))
        cat = _ids_to_rgb(f.gt_category if f.gt_category is not None else np.zeros(f.shape, int))
        tiles += [f.rgb, depth, inst, cat]
    cols = 4 if truth else cols
    h, w = tiles[0].shape[:2]
    rows = (len(tiles) + cols - 1) // cols
    canvas = np.full((rows * (h + 2), cols * (w + 2), 3), 255, dtype=np.uint8)
    for k, t in enumerate(tiles):
        r, c = divmod(k, cols)
        canvas[r * (h + 2):r * (h + 2) + h, c * (w + 2):c * (w + 2) + w] = t
    out = Path(path)
    with atomic_path(out, suffix=".png") as tmp:
        Image.fromarray(canvas).save(tmp, format="PNG", optimize=True)
    return out


def _door_ends(center: tuple[float, float], width: float, m: SceneManifest) -> tuple[tuple[float, float], ...]:
    """A door lies on a wall of constant x or y: find which by checking the room edges."""
    cx, cy = center
    for room in m.rooms:
        xs = [p[0] for p in room.polygon]
        if min(abs(cx - min(xs)), abs(cx - max(xs))) < 1e-6:
            return (cx, cy - width / 2), (cx, cy + width / 2)
    return (cx - width / 2, cy), (cx + width / 2, cy)


def render_docs(seed: int, out: str | Path) -> list[Path]:
    """The pictures under docs/sim: 12 exploration frames, 2 frames with their truth images, the map.

    ``python -m capnav.viz.scene --seed 3 --out docs/sim`` regenerates them.
    """
    from capnav.sim import ExploreConfig, Simulator, explore

    out = Path(out)
    with Simulator.from_seed(seed) as sim:
        frames = list(explore(sim, ExploreConfig(seed=seed)))
        pick = [frames[i] for i in np.linspace(0, len(frames) - 1, 12).astype(int)]
        traj = np.array([f.T_wc[:2, 3] for f in frames])
        return [frame_grid(pick, out / "frames.png", cols=4),
                frame_grid([frames[len(frames) // 3], frames[2 * len(frames) // 3]], out / "truth.png", truth=True),
                draw_scene(sim.manifest, out / "topdown.png", navigable=sim.navigable(), trajectory=traj, dpi=80)]


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser(description="Regenerate the simulator pictures of docs/sim.")
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--out", default="docs/sim")
    a = ap.parse_args()
    for p in render_docs(a.seed, a.out):
        print(p)
