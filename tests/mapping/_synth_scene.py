"""A tiny numpy ray caster for tests: axis-aligned boxes in a closed room, rendered to posed RGB-D
frames with ground-truth instance / category images (independent of the simulator package)."""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from capnav.core.frame import Frame
from capnav.core.geometry import Intrinsics, look_at_pose


@dataclass
class Box:
    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    instance: int
    category: int
    color: tuple[int, int, int]

    @property
    def center(self) -> np.ndarray:
        return (np.array(self.lo) + np.array(self.hi)) / 2


class HashEmbedder:
    """Unit vectors seeded by the text's sha256: equal texts give equal vectors, others ~orthogonal."""

    model_id = "test-hash-32"
    dim = 32

    def embed(self, texts: Sequence[str]) -> NDArray[np.float32]:
        out = []
        for t in texts:
            seed = int.from_bytes(hashlib.sha256(t.encode()).digest()[:8], "little")
            v = np.random.default_rng(seed).standard_normal(self.dim)
            out.append(v / np.linalg.norm(v))
        return np.asarray(out, dtype=np.float32).reshape(len(out), self.dim)


ROOM = ((-3.0, -3.0, 0.0), (3.0, 3.0, 2.5))


def default_boxes() -> list[Box]:
    # categories: 1 sofa, 5 table, 3 chair, 13 bookshelf, 15 lamp
    return [
        Box((-2.5, -2.5, 0.0), (-0.7, -1.6, 0.8), 1, 1, (200, 200, 210)),
        Box((0.5, 0.5, 0.0), (1.7, 1.3, 0.75), 2, 5, (120, 80, 40)),
        Box((0.7, -0.4, 0.0), (1.2, 0.1, 0.9), 3, 3, (30, 30, 160)),
        Box((-2.9, 1.0, 0.0), (-2.5, 2.4, 1.9), 4, 13, (90, 60, 30)),
        Box((2.2, -2.5, 0.0), (2.5, -2.2, 1.6), 5, 15, (240, 220, 90)),
    ]


def _slab(o: np.ndarray, d: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / d
        t1 = (lo - o) * inv
        t2 = (hi - o) * inv
    tmin = np.nanmax(np.minimum(t1, t2), axis=-1)
    tmax = np.nanmin(np.maximum(t1, t2), axis=-1)
    return tmin, tmax


def render(boxes: list[Box], T_wc: np.ndarray, K: Intrinsics, index: int = 0) -> Frame:
    h, w = K.height, K.width
    v, u = np.mgrid[0:h, 0:w]
    dc = np.stack([(u - K.cx) / K.fx, (v - K.cy) / K.fy, np.ones_like(u, dtype=float)], axis=-1).reshape(-1, 3)
    dw = dc @ T_wc[:3, :3].T
    o = T_wc[:3, 3]
    _, t_room = _slab(o, dw, np.array(ROOM[0]), np.array(ROOM[1]))
    depth = t_room.copy()
    inst = np.zeros(h * w, dtype=np.int32)
    cat = np.zeros(h * w, dtype=np.int32)
    pts = o + dw * t_room[:, None]
    rgb = np.where((pts[:, 2] < 0.01)[:, None], [150, 140, 130], [225, 225, 215]).astype(np.uint8)
    for b in boxes:
        tmin, tmax = _slab(o, dw, np.array(b.lo), np.array(b.hi))
        hit = (tmax >= tmin) & (tmin > 0) & (tmin < depth)
        depth[hit] = tmin[hit]
        inst[hit] = b.instance
        cat[hit] = b.category
        rgb[hit] = b.color
    return Frame(index=index, rgb=rgb.reshape(h, w, 3), depth=depth.reshape(h, w).astype(np.float32), K=K,
                 T_wc=T_wc, timestamp=index * 0.1, gt_instance=inst.reshape(h, w), gt_category=cat.reshape(h, w))


def orbit(n: int = 60, radius: float = 1.2, width: int = 160, height: int = 120, laps: float = 1.0,
          boxes: list[Box] | None = None) -> list[Frame]:
    """Frames from a camera at 1.2 m walking a circle and looking outwards, pitched down 20 deg."""
    K = Intrinsics.from_fov(width, height, 60.0)
    boxes = default_boxes() if boxes is None else boxes
    frames = []
    for i in range(n):
        a = 2 * np.pi * laps * i / n
        eye = np.array([radius * np.cos(a), radius * np.sin(a), 1.2])
        T = look_at_pose(eye, yaw=a + 0.3, pitch=np.deg2rad(20))
        frames.append(render(boxes, T, K, index=i))
    return frames


def look_at(eye: tuple[float, float, float], target: tuple[float, float, float]) -> np.ndarray:
    """Camera-to-world pose (z forward, x right, y down) of a camera at ``eye`` looking at ``target``."""
    e, t = np.array(eye, dtype=float), np.array(target, dtype=float)
    f = (t - e) / np.linalg.norm(t - e)
    r = np.cross(f, [0.0, 0.0, 1.0])
    r /= np.linalg.norm(r)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = r, np.cross(f, r), f, e
    return T
