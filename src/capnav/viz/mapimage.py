"""A top-down picture of a map with every object, in pixels a browser can draw over.

The picture is the mapped occupancy (free / occupied / unknown) with the colour of the highest
voxel below ``max_z`` painted on each cell (a roofless photo from above), every object's box
outlined with its map id. ``MapPicture.to_pixel`` is the world -> pixel rule the web page uses
for its overlay (north, +y, is up).
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from PIL import Image, ImageDraw

from capnav.core.grid import FREE, OCCUPIED, GridSpec
from capnav.mapping.cmap import CapNavMap

_FREE_RGB = np.array([236, 236, 232], dtype=np.float64)
_UNKNOWN_RGB = np.array([170, 170, 176], dtype=np.float64)
_WALL_RGB = np.array([40, 40, 48], dtype=np.float64)


@dataclass(frozen=True)
class MapPicture:
    """``png`` bytes of ``width`` x ``height`` pixels, ``scale`` pixels per grid cell; the grid's
    ``spec`` places it in the world."""

    png: bytes
    width: int
    height: int
    scale: int
    spec: GridSpec

    @property
    def pixels_per_metre(self) -> float:
        return self.scale / self.spec.resolution

    def to_pixel(self, xy: NDArray[np.floating]) -> NDArray[np.float64]:
        """World (..., 2) x, y -> pixel (..., 2) u (right), v (down)."""
        xy = np.asarray(xy, dtype=np.float64)
        u = (xy[..., 0] - self.spec.x0) * self.pixels_per_metre
        v = self.height - (xy[..., 1] - self.spec.y0) * self.pixels_per_metre
        return np.stack([u, v], axis=-1)

    def to_dict(self) -> dict[str, Any]:
        """What a client needs to draw in world coordinates: u = (x - x0) * ppm, v = height - (y - y0) * ppm."""
        return {"width": self.width, "height": self.height, "pixels_per_metre": self.pixels_per_metre,
                "x0": self.spec.x0, "y0": self.spec.y0}


def _top_colours(cmap: CapNavMap, max_z: float) -> tuple[NDArray[np.bool_], NDArray[np.float64]]:
    """Per cell: whether a voxel lies there, and the colour of the highest one below ``max_z``."""
    spec = cmap.occupancy.spec
    have = np.zeros((spec.rows, spec.cols), dtype=bool)
    rgb = np.zeros((spec.rows, spec.cols, 3), dtype=np.float64)
    if len(cmap.voxels) == 0:
        return have, rgb
    centres = cmap.voxels.centers()
    cols = np.asarray(cmap.voxels.colors, dtype=np.float64)
    keep = centres[:, 2] < max_z
    centres, cols = centres[keep], cols[keep]
    rc = spec.to_cell(centres[:, :2])
    ok = spec.inside(rc)
    rc, z, cols = rc[ok], centres[ok, 2], cols[ok]
    order = np.argsort(z, kind="stable")  # later (higher) voxels overwrite lower ones
    r, c = rc[order, 0], rc[order, 1]
    rgb[r, c] = cols[order]  # eq. 7 mean RGB in [0, 255]
    have[r, c] = True
    return have, rgb


#: Objects at least this tall (m) are hatched and labelled with their height (see viz.topdown).
TALL_M = 1.5


def _hatch(draw: ImageDraw.ImageDraw, box: tuple[float, float, float, float], rgb: tuple[int, int, int],
           step: int = 7) -> None:
    """Diagonal lines across ``box`` (u0, v0, u1, v1), clipped to it."""
    u0, v0, u1, v1 = (round(x) for x in box)
    w, h = u1 - u0, v1 - v0
    for k in range(-h, w, step):
        a = (u0 + max(k, 0), v0 + max(-k, 0))
        b = (u0 + min(k + h, w), v0 + min(h, w - k))
        draw.line((a, b), fill=rgb, width=1)


def map_picture(cmap: CapNavMap, max_px: int = 900, max_z: float = 2.0, labels: bool = True) -> MapPicture:
    """Draw the map (occupancy, voxel colours from above, object boxes with their map ids)."""
    spec = cmap.occupancy.spec
    cells = cmap.occupancy.cells
    img = np.tile(_UNKNOWN_RGB, (spec.rows, spec.cols, 1))
    have, top = _top_colours(cmap, max_z)
    img[cells == FREE] = _FREE_RGB
    img[have] = 0.55 * top[have] + 0.45 * img[have]  # keep free / unknown readable under the colours
    img[cells == OCCUPIED] = 0.5 * img[cells == OCCUPIED] + 0.5 * _WALL_RGB
    scale = max(1, min(8, max_px // max(spec.rows, spec.cols)))
    pic = Image.fromarray(np.clip(img[::-1], 0, 255).astype(np.uint8))  # row 0 is the lowest y: flip
    pic = pic.resize((spec.cols * scale, spec.rows * scale), Image.Resampling.NEAREST)
    out = MapPicture(b"", pic.width, pic.height, scale, spec)
    draw = ImageDraw.Draw(pic)
    for o in cmap.objects:
        (u0, v1), (u1, v0) = out.to_pixel(np.array([o.extent_min[:2], o.extent_max[:2]]))
        height = float(o.extent_max[2] - o.extent_min[2])
        if height >= TALL_M:  # its top was never seen from the camera's height: hatch it, say how tall
            _hatch(draw, (u0, v0, u1, v1), (200, 40, 40))
        draw.rectangle((u0, v0, u1, v1), outline=(200, 40, 40), width=2)
        if labels:
            draw.text((u0 + 3, v0 + 2), f"{o.id}" + (f" {height:.1f} m" if height >= TALL_M else ""),
                      fill=(20, 20, 20))
    buf = io.BytesIO()
    pic.save(buf, format="PNG", optimize=True)
    return MapPicture(buf.getvalue(), pic.width, pic.height, scale, spec)
