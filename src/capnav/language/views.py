"""View selection (paper 3.3, "frontal, high-resolution, minimally occluded views"): up to five
views per object, each stored as the full frame with the object's box drawn (what the paper's
caption prompt expects) and a tight crop.

A view's score combines its size in the image, centrality, frontality (looking at the object
from the side rather than from above), visibility (unoccluded share), truncation, detector
confidence and sharpness (variance of the Laplacian of the crop). Cheap metadata scores pick the
candidates first; only the candidates' frames are read. Views are chosen greedily with a penalty
for nearly identical viewpoints, so five views show five sides rather than one side five times.
"""

from __future__ import annotations

import io
from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from capnav.core.frame import Frame
from capnav.core.progress import track
from capnav.mapping.objects import MapObject, ObjectView, Observation


class FrameReader(Protocol):
    def __len__(self) -> int: ...

    def frame(self, index: int) -> Frame: ...


@dataclass(frozen=True)
class ViewConfig:
    max_views: int = 5  # the paper's prompt: "up to five full-frame images"
    candidates: int = 12  # per object, by metadata score, before reading pixels
    w_size: float = 0.30
    w_center: float = 0.15
    w_frontal: float = 0.15
    w_visible: float = 0.20
    w_score: float = 0.10
    w_sharp: float = 0.10
    truncated_factor: float = 0.6
    size_saturation: float = 0.12  # image fraction at which the size term saturates
    min_bearing_deg: float = 25.0  # views closer in bearing than this are penalised
    redundancy_penalty: float = 0.5
    crop_margin: float = 0.12
    box_color: tuple[int, int, int] = (255, 0, 0)
    box_width: int = 2
    frame_cache_mb: float = 512.0  # RGB kept between scoring and rendering instead of reading twice


def _metadata_score(ob: Observation, width: int, height: int, cfg: ViewConfig) -> float:
    area = max(ob.mask_area, 0) / float(width * height)
    size = min(1.0, np.sqrt(area / cfg.size_saturation))
    cx, cy = (ob.box[0] + ob.box[2]) / 2.0, (ob.box[1] + ob.box[3]) / 2.0
    off = np.hypot((cx - width / 2.0) / (width / 2.0), (cy - height / 2.0) / (height / 2.0)) / np.sqrt(2.0)
    s = (cfg.w_size * size + cfg.w_center * (1.0 - off) + cfg.w_visible * float(np.clip(ob.visibility, 0, 1))
         + cfg.w_score * float(np.clip(ob.score, 0, 1)))
    return float(s * (cfg.truncated_factor if ob.truncated else 1.0))


def sharpness(gray: NDArray[np.floating]) -> float:
    """Variance of the 4-neighbour Laplacian (a standard focus measure)."""
    if gray.shape[0] < 3 or gray.shape[1] < 3:
        return 0.0
    lap = (gray[1:-1, :-2] + gray[1:-1, 2:] + gray[:-2, 1:-1] + gray[2:, 1:-1] - 4 * gray[1:-1, 1:-1])
    return float(lap.var())


def _frontality(obj: MapObject, frame: Frame) -> tuple[float, float]:
    """(frontality in [0, 1], bearing in radians) of the camera as seen from the object."""
    cam = frame.T_wc[:3, 3]
    d = cam - obj.position
    horiz = float(np.hypot(d[0], d[1]))
    elev = abs(float(np.arctan2(d[2], max(horiz, 1e-6))))
    return float(np.cos(elev)), float(np.arctan2(d[1], d[0]))


def _crop_box(box: Sequence[float], w: int, h: int, margin: float) -> tuple[int, int, int, int]:
    x0, y0, x1, y1 = box
    mx, my = margin * (x1 - x0) + 2, margin * (y1 - y0) + 2
    c = (int(max(0, np.floor(x0 - mx))), int(max(0, np.floor(y0 - my))),
         int(min(w, np.ceil(x1 + mx))), int(min(h, np.ceil(y1 + my))))
    return (c[0], c[1], max(c[2], c[0] + 1), max(c[3], c[1] + 1))


def _png(img: NDArray[np.uint8]) -> bytes:
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(img).save(buf, format="PNG", optimize=False, compress_level=6)
    return buf.getvalue()


def render_view(rgb: NDArray[np.uint8], box: Sequence[float], cfg: ViewConfig) -> tuple[bytes, bytes]:
    """(full frame with the box drawn, tight crop) as PNG bytes."""
    from PIL import Image, ImageDraw

    img = Image.fromarray(rgb)
    ImageDraw.Draw(img).rectangle([float(box[0]), float(box[1]), float(box[2]), float(box[3])],
                                  outline=cfg.box_color, width=cfg.box_width)
    h, w = rgb.shape[:2]
    x0, y0, x1, y1 = _crop_box(box, w, h, cfg.crop_margin)
    return _png(np.asarray(img)), _png(np.ascontiguousarray(rgb[y0:y1, x0:x1]))


@dataclass
class _Candidate:
    obj: int
    ob: Observation
    meta: float
    score: float = 0.0
    bearing: float = 0.0


def _gain(c: _Candidate, picked: list[_Candidate], cfg: ViewConfig) -> float:
    limit = np.radians(cfg.min_bearing_deg)
    close = any(abs(np.angle(np.exp(1j * (c.bearing - p.bearing)))) < limit for p in picked)
    return c.score * (cfg.redundancy_penalty if close else 1.0)


def select_views_all(objects: Sequence[MapObject], reader: FrameReader, config: ViewConfig | None = None,
                     progress: bool = False) -> dict[int, list[ObjectView]]:
    """Choose and render views for many objects, reading each needed frame once (twice beyond
    the ``frame_cache_mb`` budget)."""
    cfg = config or ViewConfig()
    n_frames = len(reader)
    by_frame: dict[int, list[_Candidate]] = defaultdict(list)
    size_cache: dict[int, tuple[int, int]] = {}
    per_obj: dict[int, list[_Candidate]] = {}
    for k, obj in enumerate(objects):
        obs = [o for o in obj.observations if 0 <= o.frame_index < n_frames]
        if not obs:
            per_obj[k] = []
            continue
        if not size_cache:
            f0 = reader.frame(obs[0].frame_index)
            size_cache[0] = (f0.K.width, f0.K.height)
        w, h = size_cache[0]
        cands = sorted((_Candidate(k, o, _metadata_score(o, w, h, cfg)) for o in obs), key=lambda c: -c.meta)
        cands = cands[: cfg.candidates]
        per_obj[k] = cands
        for c in cands:
            by_frame[c.ob.frame_index].append(c)
    # Pass 1: pixel-based terms for the candidates.
    rgb_cache: dict[int, NDArray[np.uint8]] = {}
    budget = cfg.frame_cache_mb * 1e6
    for fi in track(sorted(by_frame), "scoring views", enabled=progress):
        frame = reader.frame(fi)
        if budget >= frame.rgb.nbytes:
            rgb_cache[fi] = frame.rgb
            budget -= frame.rgb.nbytes
        gray = frame.rgb.astype(np.float32).mean(axis=2) / 255.0
        hh, ww = gray.shape
        for c in by_frame[fi]:
            x0, y0, x1, y1 = _crop_box(c.ob.box, ww, hh, 0.0)
            sharp = sharpness(gray[y0:y1, x0:x1])
            front, c.bearing = _frontality(objects[c.obj], frame)
            c.score = c.meta + cfg.w_frontal * front + cfg.w_sharp * min(1.0, sharp / 0.01)
    # Greedy diverse choice per object.
    chosen: dict[int, list[_Candidate]] = {}
    for k, cands in per_obj.items():
        picked: list[_Candidate] = []
        pool = list(cands)
        while pool and len(picked) < cfg.max_views:
            best = max(pool, key=lambda c: (_gain(c, picked, cfg), -c.ob.frame_index))
            picked.append(best)
            pool.remove(best)
        chosen[k] = picked
    # Pass 2: render the chosen views.
    render: dict[int, list[_Candidate]] = defaultdict(list)
    for picked in chosen.values():
        for c in picked:
            render[c.ob.frame_index].append(c)
    views: dict[int, dict[int, ObjectView]] = defaultdict(dict)
    for fi in track(sorted(render), "rendering views", enabled=progress):
        rgb = rgb_cache[fi] if fi in rgb_cache else reader.frame(fi).rgb
        for c in render[fi]:
            full, crop = render_view(rgb, c.ob.box, cfg)
            views[c.obj][id(c)] = ObjectView(fi, tuple(float(b) for b in c.ob.box), round(c.score, 6), full, crop)  # type: ignore[arg-type]
    return {objects[k].id: [views[k][id(c)] for c in chosen[k]] for k in per_obj}


def select_views(obj: MapObject, reader: FrameReader, config: ViewConfig | None = None) -> list[ObjectView]:
    """Up to ``max_views`` rendered views of one object, best first."""
    return select_views_all([obj], reader, config)[obj.id]
