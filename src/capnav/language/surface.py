"""Surface appearance from an object's view pixels: a woven weave or a smooth surface, else nothing.

Why: a person says "the fabric sofa" or "the leather armchair"; the map can only say what its
pixels show. A weave repeats every texel or two, so it puts more energy in the finest band of
lightness detail (Gaussian scales 0-0.7 px) than in the next one (0.7-1.5 px); grain, mottle,
veins and flat paint do not. Velvet's pile hides its weave, so in pixels it is smooth.

Pixels: the central three quarters of each chosen view's crop, where the colour (CIELAB chroma and
lightness) is within ``color_tolerance`` of the object's median observed colour, away from
strong edges (the borders between faces and parts). Each view gives the RMS of the two bands over
those pixels; the object's value is the median over views. With too few pixels, or a ratio between
the two thresholds, nothing is said. The thresholds are measured by
``benchmarks/measure_evidence.py`` against the simulator's materials (README, issue 12).
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.mapping.objects import MapObject

#: Spoken material words by the surface they show: a weave, or none (velvet's pile hides it).
WOVEN_MATERIALS = frozenset({"fabric", "cotton", "linen", "wool", "woollen", "tweed", "woven", "upholstered"})
SMOOTH_MATERIALS = frozenset({"leather", "velvet", "metal", "glass", "marble", "plastic", "ceramic", "stainless",
                              "steel", "laminate", "acrylic", "porcelain", "smooth", "glossy", "shiny", "wood",
                              "wooden", "paper", "terracotta"})


@dataclass(frozen=True)
class SurfaceConfig:
    max_views: int = 5
    color_tolerance: float = 12.0  # chroma distance + lightness_weight * lightness difference (CIELAB)
    #: Half the weight let grey carpet and tiles into grey objects' pixels (a weave was then seen
    #: on grey leather and metal during development).
    lightness_weight: float = 1.0
    edge_gradient: float = 4.0  # L* per pixel (Gaussian sigma 1) above which a pixel is an edge
    min_pixels: int = 150  # surface pixels over all views below which nothing is said
    margin: float = 0.125  # share of the crop's height and width left out on each side
    #: Finest / next band RMS at or above which the surface is woven, and at or below which it is
    #: smooth (benchmarks/measure_evidence.py: share of each true material called woven / smooth).
    woven_ratio: float = 1.4
    smooth_ratio: float = 1.1
    min_fine: float = 0.3  # finest-band RMS (L*) below which a weave is too faint to call
    smooth_fine: float = 0.1  # finest-band RMS (L*) below which the surface is smooth whatever the ratio


@dataclass(frozen=True)
class Surface:
    """What the pixels say: ``word`` is "woven", "smooth" or None (weak evidence)."""

    word: str | None
    ratio: float  # finest / next band RMS, median over views (nan without pixels)
    fine: float  # finest-band RMS in L*, median over views
    pixels: int  # surface pixels over all views

    def to_list(self) -> list[Any]:
        """JSON form for ``cmap.caches["attributes"]``: [word, ratio, fine, pixels]."""
        return [self.word, round(self.ratio, 3) if np.isfinite(self.ratio) else None, round(self.fine, 3), self.pixels]

    @classmethod
    def from_list(cls, rec: list[Any]) -> Surface:
        word, ratio, fine, pixels = rec
        return cls(None if word is None else str(word), float("nan") if ratio is None else float(ratio),
                   float(fine), int(pixels))


def _bands(lab: NDArray[np.float64], ref: NDArray[np.float64], cfg: SurfaceConfig) -> tuple[float, float, int]:
    """(finest band RMS, next band RMS, pixels) of one view's surface pixels."""
    from scipy import ndimage as ndi

    h, w = lab.shape[:2]
    L = lab[..., 0]
    dist = np.hypot(lab[..., 1] - ref[1], lab[..., 2] - ref[2]) + cfg.lightness_weight * np.abs(L - ref[0])
    mask = dist < cfg.color_tolerance
    central = np.zeros_like(mask)
    mh, mw = int(h * cfg.margin), int(w * cfg.margin)
    central[mh: h - mh, mw: w - mw] = True
    edges = ndi.gaussian_gradient_magnitude(L, 1.0) > cfg.edge_gradient
    mask &= central & ~ndi.binary_dilation(edges, iterations=2)
    mask = ndi.binary_erosion(mask, iterations=2)
    n = int(mask.sum())
    if n == 0:
        return 0.0, 0.0, 0
    g1, g2 = ndi.gaussian_filter(L, 0.7), ndi.gaussian_filter(L, 1.5)
    fine = float(np.sqrt(np.mean((L - g1)[mask] ** 2)))
    mid = float(np.sqrt(np.mean((g1 - g2)[mask] ** 2)))
    return fine, mid, n


def surface_of(obj: MapObject, ref_lab: tuple[float, float, float] | None,
               config: SurfaceConfig | None = None) -> Surface:
    """The surface of ``obj`` seen in its views, around its dominant colour ``ref_lab``."""
    from PIL import Image

    from capnav.language.colors import srgb_to_lab

    cfg = config or SurfaceConfig()
    if ref_lab is None:
        return Surface(None, float("nan"), 0.0, 0)
    ref = np.asarray(ref_lab, dtype=np.float64)
    ratios, fines, total = [], [], 0
    for v in obj.views[: cfg.max_views]:
        if not v.crop_png:
            continue
        img = np.asarray(Image.open(io.BytesIO(v.crop_png)).convert("RGB"))
        if min(img.shape[:2]) < 12:
            continue
        fine, mid, n = _bands(srgb_to_lab(img), ref, cfg)
        if n < 40:
            continue
        ratios.append(fine / mid if mid > 1e-6 else 0.0)
        fines.append(fine)
        total += n
    if not ratios:
        return Surface(None, float("nan"), 0.0, total)
    ratio, fine = float(np.median(ratios)), float(np.median(fines))
    word = None
    if total >= cfg.min_pixels:
        if ratio >= cfg.woven_ratio and fine >= cfg.min_fine:
            word = "woven"
        elif ratio <= cfg.smooth_ratio or fine < cfg.smooth_fine:
            word = "smooth"
    return Surface(word, ratio, fine, total)


def material_conflict(material: str, surface: str | None) -> bool | None:
    """True when a spoken material contradicts the observed surface, False when it agrees, None when
    the word says nothing about a weave or nothing was observed."""
    if surface is None:
        return None
    m = material.lower()
    if m in WOVEN_MATERIALS:
        return surface != "woven"
    if m in SMOOTH_MATERIALS:
        return surface != "smooth"
    return None
