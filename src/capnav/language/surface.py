"""Surface appearance from an object's view pixels: a woven weave or a smooth surface, grainy or
plain, else nothing.

Why: a person says "the fabric sofa" or "the leather ottoman"; the map can only say what its
pixels show. A weave repeats every texel or two, so it puts more energy in the finest band of
lightness detail (Gaussian scales 0-0.7 px) than in the next one (0.7-1.5 px); grain, mottle,
veins and flat paint do not. Velvet's pile hides its weave, so in pixels it is smooth.

Grain: wood's stripes and leather's mottle vary the surface's brightness by a tenth or so over a
few pixels; velvet's pile, plastic, ceramic, laminate and paint barely vary it at all. The measure
is the median absolute detail of log brightness (so a dark surface and a bright one with the same
texture measure the same) in two bands, 0-1.5 px and 1.5-4 px Gaussian scales, taken within each
connected face of the surface pixels separately (normalised convolution: a face's border, the
lighting of the face next to it, is not detail). A face's smooth shading (a lamp's gradient, a
round seat's highlight) lies mostly in the coarser band, so "grainy" also needs fine detail. Low
detail in both bands is "plain". Metal's brushed streaks, marble's veins and curved faces land in
between and so decide nothing; the simulator's flat-coloured meshes (Sweet Home 3D) are plain.

Pixels: the central three quarters of each chosen view's crop, where the colour (CIELAB chroma and
lightness) is within ``color_tolerance`` of the object's median observed colour, away from
strong edges (the borders between faces and parts). Each view gives the RMS of the two bands over
those pixels; the object's value is the median over views. With too few pixels, or a ratio between
the two thresholds, nothing is said. Near black, one step of the measured brightness is coarser
than the detail a grain is called at, so no grain is said there (``resolved_grain``). The thresholds are measured by
``benchmarks/measure_evidence.py`` against the simulator's materials (docs/benchmarks.md).
"""

from __future__ import annotations

import io
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.mapping.objects import MapObject

#: Spoken material words by the surface they show: a weave, or none (velvet's pile hides it).
WOVEN_MATERIALS = frozenset({"fabric", "cotton", "linen", "wool", "woollen", "tweed", "woven", "upholstered"})
SMOOTH_MATERIALS = frozenset({"leather", "velvet", "metal", "glass", "marble", "plastic", "ceramic", "stainless",
                              "steel", "laminate", "acrylic", "porcelain", "smooth", "glossy", "shiny", "wood",
                              "wooden", "paper", "terracotta", "stone"})
#: Smooth materials by their grain: wood's stripes and leather's mottle show as grainy; velvet's
#: pile, plastic, ceramic, acrylic, laminate, glass and paper as plain. Metal's brushed streaks,
#: marble's veins and terracotta land in between and are judged by the weave only; so is stone
#: (WordNet's rock.n.02, above marble, granite and slate), as marble is.
GRAINED_MATERIALS = frozenset({"wood", "wooden", "leather"})
PLAIN_MATERIALS = frozenset({"velvet", "plastic", "ceramic", "porcelain", "acrylic", "laminate", "glass", "paper"})


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
    #: Grain: per-mille median absolute detail of log brightness (fine band 0-1.5 px + coarse band
    #: 1.5-4 px, see the module docstring), over faces of at least ``min_face`` pixels and all views
    #: together at least ``min_grain_pixels``. At or above ``grainy_detail`` with at least
    #: ``grainy_fine`` in the fine band alone the surface is grainy, at or below ``plain_detail`` plain
    #: (benchmarks/measure_evidence.py --seeds 1 2 3: wood and leather never plain, velvet, plastic,
    #: ceramic and laminate rarely grainy).
    grainy_detail: float = 7.0
    grainy_fine: float = 3.0
    plain_detail: float = 3.5
    #: Textured with less coarse than ``weave_coarse`` times the fine detail: a weave (a texel-sized
    #: checker), not grain (fabric 0.12-0.66, wood, leather, metal and marble 0.97 and up).
    weave_coarse: float = 0.8
    min_face: int = 60
    min_grain_pixels: int = 1500
    #: Views whose quietest quarter of pixels still varies by this much (per mille, finest band,
    #: median over views) come from a noisy camera: grain there may be noise, so nothing is said
    #: (rendered crops: median 0, 90th percentile 0.9; the real frames of ../shared/realdata: 1.2-2.3
    #: at their 10th percentile).
    max_noise: float = 1.5


@dataclass(frozen=True)
class Surface:
    """What the pixels say: ``word`` is "woven", "smooth" or None (weak evidence); ``grain`` is
    "woven", "grainy", "plain" or None."""

    word: str | None
    ratio: float  # finest / next band RMS, median over views (nan without pixels)
    fine: float  # finest-band RMS in L*, median over views
    pixels: int  # surface pixels over all views
    grain: str | None = None
    detail: float = 0.0  # per-mille log-brightness detail, both bands (0 without faces)
    fine_detail: float = 0.0  # the fine band's share of it

    def to_list(self) -> list[Any]:
        """JSON form for ``cmap.caches["attributes"]``: [word, ratio, fine, pixels, grain, detail,
        fine detail] (maps written before grain was measured hold the first four only)."""
        def num(v: float) -> float | None:
            return round(v, 3) if np.isfinite(v) else None

        return [self.word, num(self.ratio), round(self.fine, 3), self.pixels, self.grain, round(self.detail, 3),
                round(self.fine_detail, 3)]

    @classmethod
    def from_list(cls, rec: list[Any]) -> Surface:
        word, ratio, fine, pixels = rec[:4]
        grain, detail, fine_detail = [*rec[4:7], None, 0.0, 0.0][:3]
        return cls(None if word is None else str(word), float("nan") if ratio is None else float(ratio),
                   float(fine), int(pixels), None if grain is None else str(grain), float(detail), float(fine_detail))


def _surface_mask(lab: NDArray[np.float64], ref: NDArray[np.float64], cfg: SurfaceConfig) -> NDArray[np.bool_]:
    """One view's surface pixels: the object's colour, central, away from strong edges."""
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
    return np.asarray(ndi.binary_erosion(mask, iterations=2))


def _bands(lab: NDArray[np.float64], mask: NDArray[np.bool_]) -> tuple[float, float, int]:
    """(finest band RMS, next band RMS, pixels) of one view's surface pixels."""
    from scipy import ndimage as ndi

    L = lab[..., 0]
    n = int(mask.sum())
    if n == 0:
        return 0.0, 0.0, 0
    g1, g2 = ndi.gaussian_filter(L, 0.7), ndi.gaussian_filter(L, 1.5)
    fine = float(np.sqrt(np.mean((L - g1)[mask] ** 2)))
    mid = float(np.sqrt(np.mean((g1 - g2)[mask] ** 2)))
    return fine, mid, n


def _smooth_within(img: NDArray[np.float64], face: NDArray[np.bool_], sigma: float) -> NDArray[np.float64]:
    """Gaussian smoothing of ``img`` using the pixels of ``face`` only (normalised convolution)."""
    from scipy import ndimage as ndi

    w = face.astype(np.float64)
    return np.asarray(ndi.gaussian_filter(img * w, sigma) / np.maximum(ndi.gaussian_filter(w, sigma), 1e-6))


def _faces_detail(rgb: NDArray[np.uint8], mask: NDArray[np.bool_],
                  cfg: SurfaceConfig) -> list[tuple[int, float, float]]:
    """(pixels, fine detail, coarse detail) per connected face of ``mask``: per-mille median absolute
    log-brightness detail at Gaussian scales 0-1.5 px and 1.5-4 px."""
    from scipy import ndimage as ndi

    logv = np.log(rgb.astype(np.float64).mean(axis=2) + 4.0)  # +4: an 8-bit black is not -inf
    labels, n = ndi.label(mask)
    out = []
    for k in range(1, n + 1):
        face = labels == k
        if int(face.sum()) < cfg.min_face:
            continue
        inner = ndi.binary_erosion(face)
        m = int(inner.sum())
        if m < cfg.min_face // 2:
            continue
        g1, g2 = _smooth_within(logv, face, 1.5), _smooth_within(logv, face, 4.0)
        out.append((m, 1000.0 * float(np.median(np.abs(logv - g1)[inner])),
                    1000.0 * float(np.median(np.abs(g1 - g2)[inner]))))
    return out


def view_noise(rgb: NDArray[np.uint8], mask: NDArray[np.bool_]) -> float:
    """Per-mille finest log-brightness detail of the quietest quarter of a crop's pixels off the
    object's surface (``mask``): 0 for a rendered image (flat walls), the sensor's noise for a camera."""
    from scipy import ndimage as ndi

    logv = np.log(rgb.astype(np.float64).mean(axis=2) + 4.0)
    hp = np.abs(logv - ndi.gaussian_filter(logv, 0.7))
    off = ~ndi.binary_dilation(mask, iterations=3)
    off[:2], off[-2:], off[:, :2], off[:, -2:] = False, False, False, False
    return 1000.0 * float(np.quantile(hp[off], 0.25)) if off.sum() >= 50 else 0.0


def grain_of(faces: list[tuple[int, float, float]], cfg: SurfaceConfig,
             noise: float = 0.0) -> tuple[str | None, float, float]:
    """(word, detail, fine detail) over faces of all views, pixel-weighted; word None when weak or
    when the views are noisy (``noise`` above ``max_noise``)."""
    if not faces:
        return None, 0.0, 0.0
    a = np.asarray(faces, dtype=np.float64)
    fine = float(np.average(a[:, 1], weights=a[:, 0]))
    detail = fine + float(np.average(a[:, 2], weights=a[:, 0]))
    word = None
    if a[:, 0].sum() >= cfg.min_grain_pixels and noise <= cfg.max_noise:
        if detail >= cfg.grainy_detail and fine >= cfg.grainy_fine:
            word = "woven" if detail - fine < cfg.weave_coarse * fine else "grainy"
        elif detail <= cfg.plain_detail:
            word = "plain"
    return word, detail, fine


def brightness_step(lightness: float) -> float:
    """Per-mille step of the grain's measure (log of the mean of R, G and B, plus 4) that one third
    of an 8-bit code makes on a grey surface of CIELAB ``lightness``: the finest brightness change
    the measure can see there."""
    y = ((lightness + 16.0) / 116.0) ** 3 if lightness > 8.0 else max(lightness, 0.0) / 903.3
    v = 255.0 * (12.92 * y if y <= 0.0031308 else 1.055 * y ** (1 / 2.4) - 0.055)
    return 1000.0 * float(np.log((v + 4.0 + 1.0 / 3.0) / (v + 4.0)))


def resolved_grain(surface: Surface, lightness: float, config: SurfaceConfig | None = None) -> Surface:
    """``surface`` without a woven or grainy reading where one brightness step is coarser than the
    detail a grain is called at (``grainy_detail``): near black, a face's rounding and a minified
    texture's aliasing look like texture. A plain reading stays (no detail at all is still seen)."""
    cfg = config or SurfaceConfig()
    if surface.grain in ("woven", "grainy") and brightness_step(lightness) > cfg.grainy_detail:
        return replace(surface, grain=None)
    return surface


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
    faces: list[tuple[int, float, float]] = []
    noises = []
    for v in obj.views[: cfg.max_views]:
        if not v.crop_png:
            continue
        img = np.asarray(Image.open(io.BytesIO(v.crop_png)).convert("RGB"))
        if min(img.shape[:2]) < 12:
            continue
        lab = srgb_to_lab(img)
        mask = _surface_mask(lab, ref, cfg)
        fine, mid, n = _bands(lab, mask)
        if n < 40:
            continue
        ratios.append(fine / mid if mid > 1e-6 else 0.0)
        fines.append(fine)
        total += n
        faces += _faces_detail(img, mask, cfg)
        noises.append(view_noise(img, mask))
    if not ratios:
        return Surface(None, float("nan"), 0.0, total)
    grain, detail, fine_detail = grain_of(faces, cfg, float(np.median(noises)))
    ratio, fine = float(np.median(ratios)), float(np.median(fines))
    word = None
    if total >= cfg.min_pixels:
        if ratio >= cfg.woven_ratio and fine >= cfg.min_fine:
            word = "woven"
        elif ratio <= cfg.smooth_ratio or fine < cfg.smooth_fine:
            word = "smooth"
    return resolved_grain(Surface(word, ratio, fine, total, grain, detail, fine_detail), float(ref[0]), cfg)


def material_conflict(material: str, surface: str | None, grain: str | None = None) -> bool | None:
    """True when a spoken material contradicts the observed surface, False when it agrees, None when
    the word says nothing about what was observed. The ``grain`` (woven / grainy / plain), measured
    on more pixels of each face, decides when it was seen; else the weave ``surface`` (woven / smooth)."""
    m = material.lower()
    if grain is not None:
        if m in WOVEN_MATERIALS:
            return grain != "woven"
        if m in GRAINED_MATERIALS:
            return grain != "grainy"
        if m in PLAIN_MATERIALS:
            return grain != "plain"
        if m in SMOOTH_MATERIALS:
            return grain == "woven"
        return None
    if surface is None:
        return None
    if m in WOVEN_MATERIALS:
        return surface != "woven"
    if m in SMOOTH_MATERIALS:
        return surface != "smooth"
    return None


def material_shows(material: str) -> bool:
    """The spoken material has a grain the pixels can confirm (a weave, grain, a plain surface)."""
    m = material.lower()
    return m in WOVEN_MATERIALS or m in GRAINED_MATERIALS or m in PLAIN_MATERIALS


def grain_agrees(material: str, grain: str | None) -> bool:
    """The observed grain is what the spoken material shows (woven fabric, grainy wood, plain velvet)."""
    m = material.lower()
    return ((m in WOVEN_MATERIALS and grain == "woven") or (m in GRAINED_MATERIALS and grain == "grainy")
            or (m in PLAIN_MATERIALS and grain == "plain"))
