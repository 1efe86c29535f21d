"""An open-frame chair in front of a window and beside a cabinet, seen by a box detector: the
window's bars and the cabinet's side show through and beside the frame inside the chair's box,
touch it in the image and are apart from it in 3D. The chair keeps only its own points."""

from __future__ import annotations

import numpy as np
import pytest
from _synth_scene import Box, HashEmbedder, render
from _true_boxes import TrueBoxDetector

from capnav.core.geometry import Intrinsics
from capnav.eval.map_quality import caption_size
from capnav.mapping import MapperConfig, build_map
from capnav.mapping.lifting import lift_detection
from capnav.perception import create_encoder

K = Intrinsics.from_fov(320, 240, 70.0)
WHITE, SEAT = (240, 240, 240), (200, 60, 60)
CX, CY = 0.0, 2.2


def _chair() -> list[Box]:
    """Two side frames (a runner, a front post, an arm, a back post) of 4 cm bars, a seat and a back."""
    parts = []
    for x in (-0.27, 0.23):
        parts += [Box((CX + x, CY - 0.35, 0.05), (CX + x + 0.04, CY + 0.35, 0.09), 1, 3, WHITE),
                  Box((CX + x, CY - 0.3, 0.09), (CX + x + 0.04, CY - 0.26, 0.62), 1, 3, WHITE),
                  Box((CX + x, CY - 0.3, 0.58), (CX + x + 0.04, CY + 0.2, 0.62), 1, 3, WHITE),
                  Box((CX + x, CY + 0.2, 0.09), (CX + x + 0.04, CY + 0.24, 0.95), 1, 3, WHITE)]
    parts += [Box((CX - 0.23, CY - 0.26, 0.38), (CX + 0.23, CY + 0.2, 0.44), 1, 3, SEAT),
              Box((CX - 0.23, CY + 0.2, 0.5), (CX + 0.23, CY + 0.24, 0.95), 1, 3, SEAT)]
    return parts


WINDOW = [Box((x, 2.93, 0.3), (x + 0.06, 3.0, 2.2), 2, 0, (180, 180, 190)) for x in (-0.7, -0.15, 0.4)]
WINDOW += [Box((-0.7, 2.93, 0.3), (0.46, 3.0, 0.36), 2, 0, (180, 180, 190))]
CABINET = [Box((0.55, 2.45, 0.0), (1.3, 3.0, 0.55), 3, 12, (90, 60, 30))]
TRUE_EXTENT = np.array([0.54, 0.70, 0.95])  # the chair's frame above the floor


def _frames() -> list:  # type: ignore[type-arg]
    scene = _chair() + WINDOW + CABINET
    out = []
    for i, a in enumerate(np.linspace(-1.0, 1.0, 9)):
        eye = np.array([CX + 1.8 * np.sin(a), CY - 1.8 * np.cos(a), 1.3])
        f = eye - np.array([CX, CY, 0.45])
        f = -f / np.linalg.norm(f)
        r = np.cross(f, [0.0, 0.0, 1.0])
        r /= np.linalg.norm(r)
        T = np.eye(4)
        T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = r, np.cross(f, r), f, eye
        out.append(render(scene, T, K, index=i))
    return out


@pytest.fixture(scope="module")
def frames() -> list:  # type: ignore[type-arg]
    return _frames()


def _chair_object(frames: list, pieces: bool):  # type: ignore[no-untyped-def, type-arg]
    cmap = build_map(frames, MapperConfig(), TrueBoxDetector({1: "chair"}, grow=0.05, pieces=pieces),
                     create_encoder("label-embedding", embedder=HashEmbedder()), progress=False)
    assert len(cmap.objects) == 1
    return cmap.objects[0]


def _size_error(obj) -> float:  # type: ignore[no-untyped-def]
    w, h = caption_size(obj.extent_max - obj.extent_min)
    tw, th = caption_size(TRUE_EXTENT)
    return max(abs(w - tw) / tw, abs(h - th) / th)


def _off_chair(obj) -> float:  # type: ignore[no-untyped-def]
    lo = np.array([CX - 0.27, CY - 0.35, 0.0]) - 0.05
    hi = np.array([CX + 0.27, CY + 0.35, 0.95]) + 0.05
    return float((~np.all((obj.points >= lo) & (obj.points <= hi), axis=1)).mean())


def test_an_open_chair_keeps_only_its_own_points(frames) -> None:  # type: ignore[no-untyped-def]
    obj = _chair_object(frames, pieces=True)
    assert _off_chair(obj) <= 0.01
    assert _size_error(obj) <= 0.2


def _worst_frame(frames: list, pieces: bool) -> float:  # type: ignore[type-arg]
    """The largest share of one detection's lifted points off the chair."""
    det = TrueBoxDetector({1: "chair"}, grow=0.05, pieces=pieces)
    grid, table = np.zeros((2, 2), dtype=np.int64), np.zeros((1, 4), dtype=np.float32)
    worst = 0.0
    for f in frames:
        for d in det.detect(f):
            lifted = lift_detection(f, d, 0, grid, table)
            assert lifted is not None
            worst = max(worst, _off_chair(lifted))
    return worst


def test_each_view_keeps_only_the_chair_and_without_the_pieces_it_does_not(frames) -> None:  # type: ignore[no-untyped-def]
    """Per view, with the failure the pieces fix shown on the same frames (so the tests can fail)."""
    assert _worst_frame(frames, pieces=True) <= 0.01
    assert _worst_frame(frames, pieces=False) >= 0.03
