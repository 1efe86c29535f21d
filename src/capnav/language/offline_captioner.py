"""The offline default captioner: the paper's caption schema written from what the map observed.

Nothing here reads the scene manifest. The category comes from the object's label votes (the
detector's hint may be wrong, so the vote winner is used, not the last label); colours from its
fused point colours, or from its views' pixels when it has few points (``colors.object_colors``);
size in metres and relative to the other instances of its category; shape cues from its
top-down footprint; neighbours and room from ``SceneContext``. A lamp's colour and surface are its
shade's (the top of its points), as a plant is told apart by its pot.
"""

from __future__ import annotations

import hashlib
import io
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from capnav.language.captioner import CAPTIONERS, Caption, Captioner
from capnav.language.colors import ColorCluster, ColorConfig, object_colors
from capnav.language.context import SceneContext, canonical_label, label_of
from capnav.language.form import FormConfig, growth, outline
from capnav.language.prompts import MAX_CAPTION_WORDS
from capnav.language.surface import Surface, SurfaceConfig, surface_of
from capnav.mapping.label_fit import fitting_label
from capnav.mapping.objects import MapObject

_COUNT = {2: "two", 3: "three", 4: "four", 5: "five", 6: "six", 7: "seven", 8: "eight"}
_PLURAL = {"shelf": "shelves", "bookshelf": "bookshelves", "bench": "benches", "tv": "TVs", "couch": "couches",
           "washing machine": "washing machines", "sofa": "sofas", "bathtub": "bathtubs"}


def plural(word: str) -> str:
    if word in _PLURAL:
        return _PLURAL[word]
    if word.endswith(("s", "x", "ch", "sh")):
        return word + "es"
    return word + "s"


@dataclass(frozen=True)
class OfflineCaptionConfig:
    colors: ColorConfig = field(default_factory=ColorConfig)
    second_color_fraction: float = 0.25  # report a second colour when it covers this share
    min_points: int = 30  # fewer fused points than this: use the views' pixels for colour
    form: FormConfig = field(default_factory=FormConfig)  # shape words from the points
    surface: SurfaceConfig = field(default_factory=SurfaceConfig)  # weave and grain from the pixels
    base_fraction: float = 0.3  # lowest share of the height that holds a plant's pot
    shade_fraction: float = 0.3  # highest share of the height that holds a lamp's shade


def vote_label(obj: MapObject) -> str:
    """Category by label votes (accumulated confidence), unless the object's size rules the leading
    one out for a runner-up (``mapping.label_fit``, the rule the map's label follows), falling
    back to the current label."""
    if obj.label_votes:
        fitted = fitting_label(obj.label_votes, obj.points)[0]
        return canonical_label(fitted or max(sorted(obj.label_votes.items()), key=lambda kv: kv[1])[0])
    return label_of(obj)


def view_pixels(obj: MapObject, max_views: int = 5) -> NDArray[np.uint8]:
    """RGB pixels of the central half of each view's crop (the object, not its margin)."""
    from PIL import Image

    chunks = []
    for v in obj.views[:max_views]:
        if not v.crop_png:
            continue
        img = np.asarray(Image.open(io.BytesIO(v.crop_png)).convert("RGB"))
        h, w = img.shape[:2]
        chunks.append(img[h // 4: max(h // 4 + 1, 3 * h // 4), w // 4: max(w // 4 + 1, 3 * w // 4)].reshape(-1, 3))
    return np.concatenate(chunks) if chunks else np.zeros((0, 3), dtype=np.uint8)


def footprint_shape(obj: MapObject, cfg: OfflineCaptionConfig) -> str | None:
    """"L-shaped", "round", "long" or "rectangular" from the top-down point footprint, else None."""
    return outline(np.asarray(obj.points, dtype=np.float64), cfg.form)


#: Caption words for the observed surface (``capnav.language.surface``): a weave, grain (wood's or
#: leather's), or a plain one (velvet, plastic, paint).
SURFACE_WORDS = {"woven": "fabric", "grainy": "grainy", "plain": "smooth"}

#: Categories that grow (foliage over a pot): told apart by the pot's colour, the foliage being
#: alike (the negation of a colour reads it so too: ``retrieval.constraints.negation``).
_GROWING = {"plant"}
GROWING = frozenset(_GROWING)

#: Categories whose colour is their top's: a lamp is called by its shade ("the white lamp" with a
#: grey pole and foot), so the stand's colour, the same on every lamp, does not make them alike.
_SHADED = {"lamp"}


class ObservationCaptioner(Captioner):
    """Writes "NAME, one sentence" from the map's observations (no model, deterministic)."""

    model_id = "offline-observation-v6"  # v2: surface, rectangular and growth words; v3: "leafy", not "bushy";
    # v4: grainy / smooth surfaces; v5: a lamp's colour and surface are its shade's; v6: the name the
    # object's size allows (``mapping.label_fit``)

    def __init__(self, config: OfflineCaptionConfig | None = None) -> None:
        self.config = config or OfflineCaptionConfig()

    def own_colors(self, obj: MapObject) -> NDArray[np.uint8]:
        """The fused point colours that say the object's colour: a lamp's shade's (its points in the
        top ``shade_fraction`` of its height) when enough were fused there, else all of them."""
        rgb = np.asarray(obj.colors).reshape(-1, 3)
        if vote_label(obj) not in _SHADED:
            return rgb
        pts = np.asarray(obj.points).reshape(-1, 3)
        if len(pts) != len(rgb) or len(pts) < self.config.min_points:
            return rgb
        z = pts[:, 2]
        lo, hi = float(z.min()), float(z.max())
        top = rgb[z >= hi - self.config.shade_fraction * max(hi - lo, 1e-6)]
        return top if len(top) >= self.config.min_points else rgb

    def colors(self, obj: MapObject) -> list[ColorCluster]:
        rgb = self.own_colors(obj)
        if len(rgb) < self.config.min_points:
            px = view_pixels(obj)
            if len(px) > len(rgb):
                rgb = px
        return object_colors(rgb.reshape(-1, 3), self.config.colors) if len(rgb) else []

    def base_colors(self, obj: MapObject) -> list[ColorCluster]:
        """Colours of the lowest part of the object (a plant's pot, a lamp's foot): points below
        ``base_fraction`` of its height."""
        pts, rgb = np.asarray(obj.points), np.asarray(obj.colors)
        if len(pts) < self.config.min_points or len(rgb) != len(pts):
            return []
        z = pts[:, 2]
        lo, hi = float(z.min()), float(z.max())
        low = rgb[z <= lo + self.config.base_fraction * max(hi - lo, 1e-6)]
        return object_colors(low.reshape(-1, 3), self.config.colors) if len(low) >= 10 else []

    def surface(self, obj: MapObject) -> Surface:
        """Weave and grain from the views' pixels around the object's median observed colour."""
        from capnav.language.colors import srgb_to_lab

        rgb = self.own_colors(obj)  # a lamp's surface is its shade's
        if len(rgb) < self.config.min_points:
            px = view_pixels(obj)
            rgb = px if len(px) > len(rgb) else rgb
        ref = tuple(float(x) for x in np.median(srgb_to_lab(rgb), axis=0)) if len(rgb) else None
        return surface_of(obj, ref, self.config.surface)  # type: ignore[arg-type]

    def shapes(self, obj: MapObject, name: str | None = None) -> list[str]:
        """Observed shape words: the footprint's, then a plant's growth; empty when the points say
        nothing clearly."""
        name = name or vote_label(obj)
        pts = np.asarray(obj.points, dtype=np.float64)
        out = [w for w in (outline(pts, self.config.form),) if w]
        if name in _GROWING:
            w = growth(pts, self.config.form)
            out += [w] if w else []
        return out

    def color_phrase(self, obj: MapObject) -> str | None:
        cols = self.colors(obj)
        if not cols:
            return None
        if len(cols) > 1 and cols[1].fraction >= self.config.second_color_fraction:
            return f"{cols[0].name} and {cols[1].name}"
        return cols[0].name

    def parts(self, obj: MapObject, scene: SceneContext) -> dict[str, str]:
        """The caption's pieces by role (also used by tests and explanations)."""
        name = vote_label(obj)
        out: dict[str, str] = {"name": name}
        color = self.color_phrase(obj)
        if color:
            out["color"] = color
        if name == "plant":  # a plant is told apart by its pot
            pot = self.base_colors(obj)
            if pot:
                out["pot"] = f"in a {pot[0].name} pot"
        size = obj.size
        out["width"] = f"{max(float(size[0]), float(size[1])):.1f} m wide"
        out["height"] = f"{float(size[2]):.1f} m tall"
        shapes = self.shapes(obj, name)
        if shapes:
            out["shape"] = " ".join(shapes)
        surf = self.surface(obj)
        seen = surf.grain or ("woven" if surf.word == "woven" else None)
        if seen is not None:
            out["surface"] = SURFACE_WORDS[seen]
        if obj.id in scene.index:
            rank, count = scene.size_rank(obj)
            if count == 2:
                out["relative"] = f"the {'larger' if rank == 0 else 'smaller'} of the two {plural(name)}"
                out["size"] = "large" if rank == 0 else "small"
            elif count > 2 and rank in (0, count - 1):
                word = "largest" if rank == 0 else "smallest"
                out["relative"] = f"the {word} of {_COUNT.get(count, str(count))} {plural(name)}"
                out["size"] = "large" if rank == 0 else "small"
            near = scene.neighbours(obj)
            if near:
                out["near"] = f"next to the {label_of(near[0][0])}"
            room = scene.room_of(obj)
            if room:
                out["room"] = f"in the {room}"
        return out

    def compose(self, p: dict[str, str]) -> str:
        """"NAME, a <size> <colour> <surface> <shape> <name>, W m wide and H m tall, <relative>, <near>
        <room>." Optional clauses are dropped (relative size first) until the sentence fits 25 words."""
        adjs = " ".join(x for x in (p.get("size"), p.get("color"), p.get("surface"), p.get("shape")) if x)
        head = f"{adjs} {p['name']}" if adjs else p["name"]
        head = ("an " if head[0] in "aeiouAEIOU" else "a ") + head
        if "pot" in p:
            head += f" {p['pot']}"
        optional = [k for k in ("relative", "near", "room") if k in p]
        while True:
            parts = [f"{head}, {p['width']} and {p['height']}"]
            if "relative" in optional:
                parts.append(p["relative"])
            tail = " ".join(p[k] for k in ("near", "room") if k in optional)
            if tail:
                parts.append(tail)
            sentence = ", ".join(parts)
            if len(sentence.split()) <= MAX_CAPTION_WORDS or not optional:
                return f"{p['name'].upper()}, {sentence}."
            optional.pop(0)

    def caption(self, obj: MapObject, scene: SceneContext) -> Caption:
        return Caption(self.compose(self.parts(obj, scene)), self.model_id)

    def cache_key(self, obj: MapObject, scene: SceneContext) -> str:
        """The offline caption depends on the observations and the neighbours, not on pixels only."""
        h = hashlib.sha256(self.model_id.encode())
        h.update(repr(self.config).encode())  # thresholds change the words
        h.update(repr(sorted(obj.label_votes.items())).encode())
        h.update(np.ascontiguousarray(obj.colors).tobytes())
        h.update(np.ascontiguousarray(obj.points).tobytes())
        for v in obj.views:
            h.update(hashlib.sha256(v.crop_png).digest())
        if obj.id in scene.index:
            i = scene.index[obj.id]
            h.update(repr((scene.rooms[i], scene.size_rank(obj), [o.id for o, _ in scene.neighbours(obj)][:1],
                           len(scene.objects))).encode())
        return h.hexdigest()


@CAPTIONERS.register("offline")
def offline(**kwargs: object) -> ObservationCaptioner:
    return ObservationCaptioner(**kwargs)  # type: ignore[arg-type]
