"""Procedural material textures (wood grain, fabric weave, leather, tiles, ...), baked with the colour.

Textures are small (64x64) deterministic images: the same (pattern, colour) always gives the same
pixels, so frames stay bit-identical across runs.
"""

from __future__ import annotations

import zlib

import numpy as np
from numpy.typing import NDArray

PATTERNS = ("books", "plain", "wood", "fabric", "leather", "velvet", "metal", "marble", "ceramic", "plastic", "glass",
            "parquet", "tiles", "carpet", "paper", "laminate", "cotton", "terracotta", "acrylic")
# Materials map to a pattern; unknown materials render plain.
MATERIAL_PATTERN = {"stainless steel": "metal"}


def _noise(rng: np.random.Generator, n: int, cells: int) -> NDArray[np.float64]:
    """Smooth value noise in [0, 1]: bilinear upsampling of a coarse random grid (tileable)."""
    g = rng.random((cells, cells))
    idx = np.arange(n) * cells / n
    i0 = np.floor(idx).astype(int)
    t = idx - i0
    i1 = (i0 + 1) % cells
    a = g[i0][:, i0] * (1 - t)[None, :] + g[i0][:, i1] * t[None, :]
    b = g[i1][:, i0] * (1 - t)[None, :] + g[i1][:, i1] * t[None, :]
    return np.asarray(a * (1 - t)[:, None] + b * t[:, None])


def texture(pattern: str, rgb: tuple[int, int, int], n: int = 64) -> NDArray[np.uint8]:
    """An (n, n, 3) uint8 image of ``rgb`` modulated by ``pattern``."""
    pattern = MATERIAL_PATTERN.get(pattern, pattern)
    rng = np.random.default_rng(zlib.crc32(f"{pattern}:{rgb}".encode()))
    yy, xx = np.mgrid[0:n, 0:n] / n
    f = np.ones((n, n))
    if pattern == "wood":
        f = 0.88 + 0.12 * np.sin(2 * np.pi * (xx * 6 + 0.8 * _noise(rng, n, 4))) ** 2
    elif pattern == "fabric" or pattern == "cotton":
        f = 0.9 + 0.06 * ((np.arange(n)[:, None] + np.arange(n)[None, :]) % 2) + 0.06 * _noise(rng, n, 16)
    elif pattern == "leather":
        f = 0.82 + 0.2 * _noise(rng, n, 16) * _noise(rng, n, 8)
    elif pattern == "velvet":
        f = 0.85 + 0.2 * _noise(rng, n, 4)
    elif pattern == "metal":
        f = 0.92 + 0.08 * _noise(rng, n, 32)[:, :1].repeat(n, axis=1)
    elif pattern == "marble":
        f = 0.9 + 0.1 * np.abs(np.sin(2 * np.pi * (xx + yy + 1.5 * _noise(rng, n, 4))))
    elif pattern in ("ceramic", "acrylic", "plastic"):
        f = 0.97 + 0.03 * _noise(rng, n, 2)
    elif pattern == "glass":
        f = 0.9 + 0.15 * (np.abs(xx - yy) < 0.08)
    elif pattern == "parquet":
        plank = (np.floor(yy * 4) + np.floor(xx * 1.0 + 0.5 * (np.floor(yy * 4) % 2))) % 3
        f = 0.86 + 0.06 * plank + 0.05 * np.sin(2 * np.pi * xx * 9 + 3 * _noise(rng, n, 4)) \
            - 0.25 * ((yy * 4) % 1 < 0.04)
    elif pattern == "tiles":
        f = 1.0 - 0.35 * (((xx * 2) % 1 < 0.04) | ((yy * 2) % 1 < 0.04)) + 0.04 * _noise(rng, n, 8)
    elif pattern == "carpet":
        f = 0.85 + 0.15 * rng.random((n, n)) * _noise(rng, n, 8)
    elif pattern == "books":  # vertical spines of random widths and colours; rgb only seeds the variant
        from capnav.sim.palette import BOOK_COLORS

        img = np.zeros((n, n, 3))
        x = 0
        while x < n:
            bw = int(rng.integers(3, 8))
            img[:, x:x + bw] = BOOK_COLORS[int(rng.integers(len(BOOK_COLORS)))]
            img[:, x + bw - 1:x + bw] *= 0.6  # a dark gap between books
            top = int(rng.integers(0, n // 5))
            img[:top, x:x + bw] = 30  # shorter books leave shadow above
            x += bw
        return img.astype(np.uint8)
    elif pattern in ("paper", "laminate", "terracotta"):
        f = 0.93 + 0.07 * _noise(rng, n, 8)
    img = np.clip(np.asarray(rgb, dtype=np.float64)[None, None, :] * f[:, :, None], 0, 255)
    return img.astype(np.uint8)
