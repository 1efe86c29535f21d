"""Colour naming in CIELAB with CIEDE2000, robust to shading.

Why: a caption must say "grey sofa" for a grey sofa whether its points were seen in sunlight or in
the shadow of a wall. Shading in a renderer or a camera scales linear RGB, which mostly moves
CIELAB lightness and barely moves hue. So we (1) cluster an object's point colours in Lab (k-means,
seeded) and keep the dominant clusters, (2) estimate each cluster's unshaded colour from its
best-lit points (an upper lightness percentile, shading only darkens), and (3) name it with
CIEDE2000 using ``kL = 2`` (the textile-industry weighting that halves lightness differences).

The lexicon holds common English colour words with typical sRGB values (mostly from the xkcd
colour-name survey, plus wood tones). Queries use the same lexicon, so "silver" can match an
object captioned "light grey" by colour distance rather than by exact word.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from capnav.core.colour import ciede2000, srgb_to_lab
from capnav.core.errors import InputError

F64 = NDArray[np.float64]

#: Colour word -> typical sRGB. Multi-word names first so that parsing prefers them.
LEXICON: dict[str, tuple[int, int, int]] = {
    "light blue": (149, 208, 252),
    "light grey": (216, 220, 214),
    "dark grey": (54, 55, 55),
    "dark brown": (52, 28, 2),
    "white": (250, 250, 248),
    "black": (12, 12, 14),
    "grey": (146, 149, 145),
    "silver": (197, 201, 199),
    "cream": (255, 250, 205),
    "beige": (230, 218, 166),
    "tan": (209, 178, 111),
    "brown": (101, 55, 0),
    "oak": (190, 150, 100),
    "walnut": (93, 62, 40),
    "red": (229, 0, 0),
    "terracotta": (202, 102, 65),
    "orange": (249, 115, 6),
    "mustard": (206, 179, 1),
    "yellow": (255, 230, 20),
    "olive": (110, 117, 14),
    "green": (21, 176, 26),
    "teal": (2, 147, 134),
    "blue": (3, 67, 223),
    "navy": (1, 21, 62),
    "purple": (126, 30, 156),
    "pink": (255, 129, 192),
}

#: Spelling variants and near-synonyms a user may type.
ALIASES: dict[str, str] = {
    "gray": "grey", "light gray": "light grey", "dark gray": "dark grey", "navy blue": "navy",
    "off-white": "cream", "off white": "cream", "ivory": "cream", "charcoal": "dark grey",
    "violet": "purple", "maroon": "red", "crimson": "red", "golden": "mustard", "gold": "mustard",
    "chrome": "silver", "steel": "silver", "turquoise": "teal", "khaki": "tan",
}


NAMES: tuple[str, ...] = tuple(LEXICON)
LEX_LAB: F64 = srgb_to_lab(np.array([LEXICON[n] for n in NAMES]))


def canonical_color(word: str) -> str | None:
    """Lexicon name of a colour word or alias (``gray`` -> ``grey``), else None."""
    w = word.strip().lower()
    if w in LEXICON:
        return w
    return ALIASES.get(w)


#: Understood in queries but not used to name colours: "silver" is a metallic sheen that a
#: colour alone cannot show, so such surfaces are named "light grey" (a ΔE00 of about 5 away).
QUERY_ONLY: frozenset[str] = frozenset({"silver"})
_NAMING = np.array([n not in QUERY_ONLY for n in NAMES])


def name_lab(lab: NDArray[np.floating], kL: float = 2.0) -> tuple[str, float]:
    """Nearest naming colour of one Lab colour and its CIEDE2000 distance."""
    d = ciede2000(np.asarray(lab, dtype=np.float64)[None, :], LEX_LAB, kL=kL)
    d = np.where(_NAMING, d, np.inf)
    i = int(np.argmin(d))
    return NAMES[i], float(d[i])


@dataclass(frozen=True)
class ColorCluster:
    name: str
    lab: tuple[float, float, float]  # estimated unshaded colour
    fraction: float  # share of the object's points
    distance: float  # CIEDE2000 to the named colour


@dataclass(frozen=True)
class ColorConfig:
    max_clusters: int = 4
    max_points: int = 4000  # subsample for speed
    iterations: int = 12
    lit_percentile: float = 85.0  # shading only darkens: best-lit points approximate the albedo
    min_fraction: float = 0.08  # clusters smaller than this are not reported
    kL: float = 2.0
    luminance_weight: float = 0.04  # chromaticity units per e-fold of luminance
    merge_distance: float = 0.05  # k-means clusters closer than this are one surface (lit + shaded)
    seed: int = 0


def _shading_invariant_features(rgb: NDArray[np.generic], luminance_weight: float) -> F64:
    """Chromaticity of linear RGB (unchanged when shading scales the light) plus a weak
    log-luminance term, so that white and black parts still separate but lit and shaded faces
    of one surface do not."""
    c = np.asarray(rgb, dtype=np.float64) / 255.0
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4) + 1e-3
    s = lin.sum(axis=1, keepdims=True)
    chroma = lin[:, :2] / s
    y = np.log(lin @ np.array([0.2126, 0.7152, 0.0722]))
    return np.concatenate([chroma, luminance_weight * y[:, None]], axis=1)


def _merge_close(feats: F64, labels: NDArray[np.intp], dist: float) -> NDArray[np.intp]:
    """Single-linkage merge of cluster centres closer than ``dist`` (k-means splits a uniformly
    coloured but unevenly lit surface along luminance)."""
    ids = list(np.unique(labels))
    centers = {j: feats[labels == j].mean(0) for j in ids}
    parent = {j: j for j in ids}

    def root(j: int) -> int:
        while parent[j] != j:
            j = parent[j]
        return j

    for i, a in enumerate(ids):
        for b in ids[i + 1:]:
            if np.linalg.norm(centers[a] - centers[b]) < dist:
                parent[root(b)] = root(a)
    return np.array([root(int(j)) for j in labels], dtype=np.intp)


def _kmeans(x: F64, k: int, iters: int, rng: np.random.Generator) -> NDArray[np.intp]:
    """Plain k-means with k-means++ seeding."""
    centers = [x[rng.integers(len(x))]]
    for _ in range(1, k):
        d2 = np.min(((x[:, None, :] - np.array(centers)[None]) ** 2).sum(-1), axis=1)
        if d2.sum() <= 0:
            break
        centers.append(x[rng.choice(len(x), p=d2 / d2.sum())])
    c = np.array(centers)
    labels = np.zeros(len(x), dtype=np.intp)
    for _ in range(iters):
        labels = np.argmin(((x[:, None, :] - c[None]) ** 2).sum(-1), axis=1)
        new = np.array([x[labels == j].mean(0) if np.any(labels == j) else c[j] for j in range(len(c))])
        if np.allclose(new, c):
            break
        c = new
    return labels


def object_colors(rgb: NDArray[np.generic], config: ColorConfig | None = None) -> list[ColorCluster]:
    """Dominant named colours of an object's point colours (N, 3) uint8, largest share first."""
    cfg = config or ColorConfig()
    rgb = np.asarray(rgb)
    if rgb.ndim != 2 or rgb.shape[1] != 3:
        raise InputError(f"colours must be (N, 3), got {rgb.shape}")
    if len(rgb) == 0:
        return []
    rng = np.random.default_rng(cfg.seed)
    if len(rgb) > cfg.max_points:
        rgb = rgb[np.sort(rng.choice(len(rgb), cfg.max_points, replace=False))]
    lab = srgb_to_lab(rgb)
    feats = _shading_invariant_features(rgb, cfg.luminance_weight)
    k = int(min(cfg.max_clusters, max(1, len(lab) // 20)))
    labels = _kmeans(feats, k, cfg.iterations, rng) if k > 1 else np.zeros(len(lab), dtype=np.intp)
    labels = _merge_close(feats, labels, cfg.merge_distance)
    out: list[ColorCluster] = []
    for j in np.unique(labels):
        members = lab[labels == j]
        frac = len(members) / len(lab)
        if frac < cfg.min_fraction and out:
            continue
        cut = np.percentile(members[:, 0], cfg.lit_percentile)
        lit = members[members[:, 0] >= cut - 1e-9].mean(axis=0)
        name, dist = name_lab(lit, kL=cfg.kL)
        out.append(ColorCluster(name, (float(lit[0]), float(lit[1]), float(lit[2])), float(frac), dist))
    out.sort(key=lambda c: -c.fraction)
    # Merge clusters that received the same name.
    merged: dict[str, ColorCluster] = {}
    for c in out:
        if c.name in merged:
            m = merged[c.name]
            merged[c.name] = ColorCluster(m.name, m.lab, m.fraction + c.fraction, m.distance)
        else:
            merged[c.name] = c
    return sorted(merged.values(), key=lambda c: -c.fraction)


# -- colours as people say them (queries only; naming keeps the palette above) -----------------

#: Shade words people use that the naming palette has no entry for, with typical sRGB values from
#: the xkcd colour-name survey. Understood in queries, never used to name a measured colour.
SHADES: dict[str, tuple[int, int, int]] = {
    "burgundy": (97, 0, 35), "wine": (128, 1, 63), "maroon": (101, 0, 33), "crimson": (140, 0, 15),
    "scarlet": (190, 1, 25), "coral": (252, 90, 80), "salmon": (255, 121, 108), "peach": (255, 176, 124),
    "rust": (168, 60, 9), "burnt orange": (192, 78, 1), "ochre": (191, 144, 5), "gold": (219, 180, 12),
    "golden": (219, 180, 12), "sand": (226, 202, 118), "taupe": (185, 162, 129), "khaki": (170, 166, 98),
    "ivory": (255, 255, 203), "off-white": (255, 255, 228), "eggshell": (255, 255, 212), "charcoal": (52, 56, 55),
    "slate": (81, 101, 114), "ash": (190, 190, 190), "magenta": (194, 0, 120), "hot pink": (255, 2, 141),
    "rose": (207, 98, 117), "mauve": (174, 113, 129), "lilac": (206, 162, 253), "lavender": (199, 159, 239),
    "violet": (154, 14, 234), "plum": (88, 15, 65), "indigo": (56, 2, 130), "royal blue": (5, 4, 170),
    "cobalt": (30, 72, 143), "sky blue": (117, 187, 253), "baby blue": (162, 207, 254), "aqua": (19, 234, 201),
    "turquoise": (6, 194, 172), "mint": (159, 254, 176), "sage": (135, 174, 115), "lime": (170, 255, 50),
    "emerald": (1, 160, 73), "forest green": (6, 71, 12), "olive green": (103, 122, 4), "chrome": (197, 201, 199),
    "steel": (197, 201, 199),
}

#: Modifiers: how a word moves a colour in CIELAB (lightness change towards white/black as a
#: fraction, chroma factor). "-ish" words ("reddish") are the base colour made duller.
_MODIFIERS: dict[str, tuple[float, float]] = {
    "light": (0.45, 0.75), "pale": (0.5, 0.6), "pastel": (0.45, 0.55), "soft": (0.25, 0.8),
    "dark": (-0.45, 0.9), "deep": (-0.35, 1.1), "rich": (-0.2, 1.15), "bright": (0.1, 1.25), "vivid": (0.0, 1.3),
    "dull": (0.0, 0.6), "muted": (0.0, 0.6), "dusty": (0.05, 0.55), "faded": (0.2, 0.55),
}
_ISH = (0.0, 0.7)
#: Wood tones named by their lightness ("dark wooden" is walnut, "light wood" oak).
_WOODS = {"light wood": "oak", "light wooden": "oak", "dark wood": "walnut", "dark wooden": "walnut"}


def _base_lab(word: str) -> F64 | None:
    w = word.strip().lower()
    name = canonical_color(w)
    if name is not None:
        return np.asarray(LEX_LAB[NAMES.index(name)], dtype=np.float64)
    if w in SHADES:
        return srgb_to_lab(np.array(SHADES[w], dtype=np.float64))
    return None


def _de_ish(word: str) -> str | None:
    """'reddish' -> 'red', 'greyish' -> 'grey', 'bluish' -> 'blue', 'orangey' -> 'orange', 'creamy'
    -> 'cream'; None when the word is no such derivation of a colour word."""
    for suffix in ("ish", "ey", "y"):
        if word.endswith(suffix) and len(word) > len(suffix) + 2:
            stem = word[: -len(suffix)]
            for cand in (stem, stem + "e", stem[:-1] if len(stem) > 3 and stem[-1] == stem[-2] else stem):
                if _base_lab(cand) is not None:
                    return cand
    return None


def _modify(lab: F64, light: float, chroma: float) -> F64:
    L, a, b = (float(v) for v in lab)
    L = L + (100.0 - L) * light if light >= 0 else L * (1.0 + light)
    return np.array([L, a * chroma, b * chroma], dtype=np.float64)


def color_lab(phrase: str) -> F64 | None:
    """CIELAB point of a colour as people say it ("reddish", "light grey", "off-white", "navy",
    "dark wooden", "pale pinkish"), else None. Palette words keep their palette point; modifiers
    move it (lighter / darker / duller / brighter)."""
    words = phrase.strip().lower().replace("-coloured", "").replace("-colored", "").split()
    if not words:
        return None
    text = " ".join(words)
    if text in _WOODS:
        return np.asarray(LEX_LAB[NAMES.index(_WOODS[text])], dtype=np.float64)
    base = _base_lab(text)
    if base is not None:
        return base
    head = words[-1]
    lab = _base_lab(head)
    if lab is None:
        stem = _de_ish(head)
        if stem is None:
            return None
        lab = _modify(_base_lab(stem), *_ISH)  # type: ignore[arg-type]
    for mod in reversed(words[:-1]):
        m = mod.removesuffix("ish")
        if m in _MODIFIERS:
            lab = _modify(lab, *_MODIFIERS[m])
        else:
            stem = _de_ish(mod)
            if stem is None:
                return None  # "yellow terracotta" is a colour and a material, not one colour
            lab = 0.75 * lab + 0.25 * _base_lab(stem)  # type: ignore[operator]  # "greenish blue"
    return lab


def is_color_phrase(phrase: str) -> bool:
    return color_lab(phrase) is not None


def color_distance(phrase: str, lab: NDArray[np.floating] | tuple[float, float, float], kL: float = 2.0) -> float:
    """CIEDE2000 (``kL`` = 2, as for naming) between a spoken colour and a measured colour; raises
    ``InputError`` for a phrase that names no colour. "purple" vs a pink object is about 20."""
    target = color_lab(phrase)
    if target is None:
        raise InputError(f"unknown colour word {phrase!r}")
    return float(ciede2000(target, np.asarray(lab, dtype=np.float64), kL=kL))


def color_agreement(word: str, lab: NDArray[np.floating] | tuple[float, float, float], scale: float = 12.0,
                    kL: float = 2.0) -> float:
    """How well a colour word or phrase fits a measured colour, in (0, 1]: exp(-ΔE00 / scale)."""
    a = np.asarray(lab, dtype=np.float64).reshape(-1)
    if a.shape != (3,):
        return float(np.exp(-color_distance(word, lab, kL=kL) / scale))
    return _agreement(word, float(a[0]), float(a[1]), float(a[2]), float(scale), float(kL))


@lru_cache(maxsize=65536)
def _agreement(word: str, L: float, a: float, b: float, scale: float, kL: float) -> float:
    """``color_agreement`` kept per (word, measured colour): a map's objects keep their colours, so
    the verifier of a running server meets the same pairs ask after ask (the CIEDE2000 formula in
    numpy costs ~0.1 ms a pair)."""
    return float(np.exp(-color_distance(word, np.array([L, a, b]), kL=kL) / scale))


# -- colour families: what a spoken word covers ---------------------------------------------------

#: The basic colour terms of English (Berlin and Kay, 1969): the words people use for a whole
#: range of shades that the palette names more finely ("mustard is a yellow").
BASIC: tuple[str, ...] = ("white", "black", "grey", "red", "orange", "yellow", "green", "blue", "purple", "pink",
                          "brown")
#: ΔE00 (kL = 2) within which a named colour is a shade of its nearest basic term: the distance at
#: which the verifier's agreement exp(-ΔE00 / 12) reaches its "is that colour" level (0.43, beside
#: ``OfflineVerifierConfig.color_match``), so a basic term covers only colours it would match itself.
FAMILY_RADIUS = 10.0
#: A shade belongs to a basic term only when every other basic term is at least this many times
#: farther: indigo (purple 8.6, blue 13.7) and silver (white 5.9, grey 7.5) lie between two terms
#: and belong to neither; mustard (yellow 6.9, green 27.5) is a yellow.
FAMILY_MARGIN = 2.0


def _named_labs() -> dict[str, F64]:
    """Every named colour (palette and shade words, aliases resolved) with its CIELAB point."""
    out = {n: np.asarray(LEX_LAB[i], dtype=np.float64) for i, n in enumerate(NAMES)}
    for w in SHADES:
        if canonical_color(w) is None:  # "maroon" is an alias of "red", not a colour of its own
            out[w] = srgb_to_lab(np.array(SHADES[w], dtype=np.float64))
    return out


_NAMED: dict[str, F64] = _named_labs()
_BASIC_LAB: F64 = np.array([_NAMED[b] for b in BASIC])


@lru_cache(maxsize=1024)
def family(word: str, radius: float = FAMILY_RADIUS) -> tuple[str, ...]:
    """The colours a spoken word covers, the word itself first: the named colours whose head word
    it is ("light blue" and "sky blue" for blue, "forest green" for green) and, for a basic term,
    the named colours within ``radius`` ΔE00 of it and ``FAMILY_MARGIN`` times nearer to it than to
    any other basic term (mustard for yellow, walnut for brown, light grey for white). A word
    outside the palette (a shade or a modified colour, "pale pink") covers itself only."""
    w = word.strip().lower()
    name = canonical_color(w) or w
    out = [name]
    for n, lab in _NAMED.items():
        if n == name:
            continue
        if len(n.split()) > 1 and n.split()[-1] == name:
            out.append(n)
        elif name in BASIC:
            d = ciede2000(lab[None], _BASIC_LAB, kL=2.0)
            k, second = np.argsort(d)[:2]
            if BASIC[k] == name and d[k] <= radius and d[second] >= FAMILY_MARGIN * d[k]:
                out.append(n)
    return tuple(out)


# -- a plain hue word covers its dark shades ------------------------------------------------------

#: CIELAB chroma above which a basic term names a hue. White, grey and black (chroma under 3) have
#: none: their lightness is what tells them apart, so a darker white is grey, never "a dark white".
HUE_CHROMA = 20.0
#: Agreement lost per unit of darkening along a hue's shade ray (at t = 0.7, a navy for "blue",
#: 0.91 of its agreement with the ray point): the word's own colour still ranks first when both
#: a blue and a navy object are in the map.
DARK_DISCOUNT = 0.3
_RAY_T = np.round(np.arange(1.0, 0.19, -0.05), 2)  # lightness factors along the ray, focal first
_RAY_S = (1.0, 1.25)  # chroma factors: the focal chroma and a more saturated shade


@lru_cache(maxsize=64)
def shade_ray(word: str) -> tuple[tuple[tuple[float, float, float], float], ...]:
    """The dark and saturated shades a plain basic hue term covers, as (CIELAB point, lightness
    factor t) pairs, the word's own colour first: its focal colour scaled towards black (t * Lab,
    what a darker surface of the same chromaticity is, navy for blue, forest green for green) and a
    more saturated version of each, for as long as the shade belongs to the term by the family rule
    (nearest basic term, every other one ``FAMILY_MARGIN`` times farther: a dark orange becomes
    brown and leaves "orange"). Any other word (an achromatic term, a shade word, a colour with a
    lightness modifier such as "light blue" or "dark blue") has its own point only."""
    w = word.strip().lower()
    name = canonical_color(w)
    lab = color_lab(w)
    if lab is None:
        return ()
    focal = np.asarray(lab, dtype=np.float64)
    out = [((float(focal[0]), float(focal[1]), float(focal[2])), 1.0)]
    if name not in BASIC or float(np.hypot(focal[1], focal[2])) < HUE_CHROMA:
        return tuple(out)
    own = BASIC.index(name)
    for s in _RAY_S:
        for t in _RAY_T:
            if t == 1.0 and s == 1.0:
                continue
            p = np.array([focal[0] * t, focal[1] * t * s, focal[2] * t * s])
            d = ciede2000(p[None], _BASIC_LAB, kL=2.0)
            others = np.delete(d, own)
            if int(np.argmin(d)) != own or float(others.min()) < FAMILY_MARGIN * float(d[own]):
                break  # the shade has left the term; darker ones are farther still
            out.append(((float(p[0]), float(p[1]), float(p[2])), float(t)))
    return tuple(out)


def term_agreement(word: str, lab: NDArray[np.floating] | tuple[float, float, float], scale: float = 12.0,
                   kL: float = 2.0) -> float:
    """How well a spoken colour fits a measured colour, in (0, 1], counting the dark shades a plain
    hue term covers (``shade_ray``): the best exp(-ΔE00 / scale) over the word's own colour and its
    shades, each shade's discounted by ``DARK_DISCOUNT`` per unit of darkening. "blue" fits a navy
    object nearly as well as a blue one and a light blue one no better than ``color_agreement``
    (lighter than the word's colour is not on the ray); every other word equals
    ``color_agreement``."""
    a = np.asarray(lab, dtype=np.float64).reshape(-1)
    if a.shape != (3,):
        raise InputError(f"a colour is 3 numbers, got {a.shape}")
    return _term_agreement(word.strip().lower(), float(a[0]), float(a[1]), float(a[2]), float(scale), float(kL))


@lru_cache(maxsize=65536)
def _term_agreement(word: str, L: float, a: float, b: float, scale: float, kL: float) -> float:
    ray = shade_ray(word)
    if len(ray) <= 1:
        return _agreement(word, L, a, b, scale, kL)
    pts = np.array([p for p, _ in ray])
    ts = np.array([t for _, t in ray])
    d = ciede2000(np.array([L, a, b])[None], pts, kL=kL)
    return float(np.max(np.exp(-d / scale) * (1.0 - DARK_DISCOUNT * (1.0 - ts))))


#: Share of a lighter shade's agreement, against a darker one's, when the plain hue term was said:
#: "blue" of a light blue object counts half of what it counts for a royal blue one, so a full or
#: dark shade of the hue ranks first and "light blue" is what asks for the light one.
LIGHT_SHADE_SHARE = 0.5


def lighter_shade(word: str, shade: str) -> bool:
    """Whether ``shade`` is a lighter shade of the hue term ``word`` (light blue, sky blue for
    blue): the word names a hue (``HUE_CHROMA``) and the shade's lightness is above its colour's.
    Never for white, grey or black, whose shades differ by lightness alone."""
    w, s = color_lab(word), color_lab(shade)
    if w is None or s is None or float(np.hypot(w[1], w[2])) < HUE_CHROMA:
        return False
    return float(s[0]) > float(w[0])
