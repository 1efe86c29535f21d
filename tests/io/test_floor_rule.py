"""The floor is the lowest well-supported plane under the cameras, not the plane with the most points.

A recording made looking down at a large table holds several times more table-top points than
floor points (the floor shows only at the image edges). These scenes are ray-cast here from boxes
(a room, a big table, a counter), so the depth is exact and the truth is known: the cameras are
1.35 m above the floor and 0.6 m above the table top.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from capnav.cli import app
from capnav.core.errors import InputError
from capnav.core.frame import Frame
from capnav.core.geometry import Intrinsics, look_at_pose
from capnav.io.align import floor_alignment, parse_up
from capnav.io.dataset import DatasetReader
from capnav.io.export import tilt_matrix, write_tum

K = Intrinsics.from_fov(96, 72, 58.0)
ROOM = (-2.5, -2.0, 2.5, 2.0)  # x0, y0, x1, y1 of the walls' inner faces
TABLE_TOP = 0.75


def boxes(table: tuple[float, float, float, float], top: float) -> np.ndarray:
    """(N, 2, 3) min/max corners: floor slab, ceiling, four walls, the table top slab and its legs."""
    x0, y0, x1, y1 = ROOM
    tx0, ty0, tx1, ty1 = table
    b = [[(x0 - 1, y0 - 1, -0.2), (x1 + 1, y1 + 1, 0.0)], [(x0 - 1, y0 - 1, 2.6), (x1 + 1, y1 + 1, 2.8)],
         [(x0 - 0.2, y0, 0), (x0, y1, 2.6)], [(x1, y0, 0), (x1 + 0.2, y1, 2.6)],
         [(x0, y0 - 0.2, 0), (x1, y0, 2.6)], [(x0, y1, 0), (x1, y1 + 0.2, 2.6)],
         [(tx0, ty0, top - 0.04), (tx1, ty1, top)]]
    for lx, ly in ((tx0, ty0), (tx1 - 0.06, ty0), (tx0, ty1 - 0.06), (tx1 - 0.06, ty1 - 0.06)):
        b.append([(lx, ly, 0.0), (lx + 0.06, ly + 0.06, top - 0.04)])
    return np.array(b, dtype=np.float64)


def raycast(T_wc: np.ndarray, B: np.ndarray) -> np.ndarray:
    """z-depth of the nearest box along every pixel's ray (slab method, vectorised over boxes)."""
    u, v = np.meshgrid(np.arange(K.width), np.arange(K.height))
    d_cam = np.stack([(u - K.cx) / K.fx, (v - K.cy) / K.fy, np.ones_like(u, dtype=float)], -1).reshape(-1, 3)
    d = d_cam @ T_wc[:3, :3].T
    o = T_wc[:3, 3]
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / d
        t0 = (B[None, :, 0, :] - o) * inv[:, None, :]
        t1 = (B[None, :, 1, :] - o) * inv[:, None, :]
    tmin = np.nanmax(np.minimum(t0, t1), axis=2)
    tmax = np.nanmin(np.maximum(t0, t1), axis=2)
    hit = (tmax >= tmin) & (tmax > 0)
    t = np.where(hit, np.maximum(tmin, 0), np.inf).min(axis=1)  # ray length per unit camera z
    return np.where(np.isfinite(t), t, 0.0).reshape(K.height, K.width).astype(np.float32)


def table_views(n: int = 8, height: float = 1.35, pitch_deg: float = 70.0,
                table: tuple[float, float, float, float] = (-1.4, -0.9, 1.4, 0.9)) -> list[Frame]:
    """A camera walking around a 2.8 x 1.8 m table, pitched 70 deg down at it from above its edge."""
    B = boxes(table, TABLE_TOP)
    out = []
    for i in range(n):
        a = 2 * math.pi * i / n
        eye = np.array([1.3 * math.cos(a), 0.85 * math.sin(a), height])
        yaw = math.atan2(-eye[1], -eye[0])
        T = look_at_pose(eye, yaw, math.radians(pitch_deg))
        depth = raycast(T, B)
        rgb = np.full((K.height, K.width, 3), 128, np.uint8)
        out.append(Frame(index=i, rgb=rgb, depth=depth, K=K, T_wc=T, timestamp=i / 30.0))
    return out


def _views(frames: list[Frame], W: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    return [(f.depth, W @ f.T_wc) for f in frames]


def test_the_scene_has_more_table_than_floor() -> None:
    """The premise: the table top holds several times the floor's points (else the test tests nothing)."""
    from capnav.core.geometry import backproject

    f = table_views()
    P = np.concatenate([backproject(x.depth, K, x.T_wc)[0] for x in f])
    on_table = int((np.abs(P[:, 2] - TABLE_TOP) < 0.02).sum())
    on_floor = int((np.abs(P[:, 2]) < 0.02).sum())
    assert on_table > 20 * on_floor > 0, (on_table, on_floor)


@pytest.mark.parametrize("tilt", ["0,0,0", "-118,0,0", "-100,15,40"])
def test_floor_under_a_big_table(tilt: str) -> None:
    """In any recording world (z up, a pitched first camera's frame, tilted and turned), up is found
    and the floor is the floor: cameras 1.35 m above it, the table top the runner-up plane."""
    frames = table_views()
    W = tilt_matrix(tilt)
    a = floor_alignment(_views(frames, W), K, "auto", poses=np.stack([W @ f.T_wc for f in frames]))
    assert a.info["facts"]["camera_height_median_m"] == pytest.approx(1.35, abs=0.03)
    up = W[:3, :3] @ np.array([0.0, 0.0, 1.0])
    assert np.degrees(np.arccos(np.clip(np.dot(a.info["up_in_recording"], up), -1, 1))) < 2.0
    runner = a.info["floor_runner_up"]
    assert runner is not None and runner["height_m"] == pytest.approx(TABLE_TOP, abs=0.03)
    assert runner["points"] > 10 * a.info["floor_points"]
    assert 0.5 <= a.info["floor_confidence"] <= 1.0


def test_up_as_any_direction() -> None:
    """--up x,y,z names a direction in the recording's frame: accepted near the truth, refused far off."""
    frames = table_views()
    W = tilt_matrix("-100,15,40")
    up = W[:3, :3] @ np.array([0.0, 0.0, 1.0])
    near = up + np.array([0.05, -0.03, 0.02])
    spec = ",".join(f"{v:.4f}" for v in near)
    assert np.allclose(parse_up(spec), near / np.linalg.norm(near), atol=1e-3)
    a = floor_alignment(_views(frames, W), K, spec, poses=np.stack([W @ f.T_wc for f in frames]))
    assert a.info["facts"]["camera_height_median_m"] == pytest.approx(1.35, abs=0.03)
    wrong = ",".join(f"{v:.4f}" for v in W[:3, :3] @ np.array([1.0, 0.0, 0.0]))
    with pytest.raises(InputError, match="contradicts the recording"):
        floor_alignment(_views(frames, W), K, wrong, poses=np.stack([W @ f.T_wc for f in frames]))
    for bad in ("1,2", "0,0,0", "a,b,c", "nan,0,1"):
        with pytest.raises(InputError, match="--up"):
            parse_up(bad)


def test_cli_prints_the_floor_confidence_and_runner_up(tmp_path: Path) -> None:
    frames = table_views()
    W = tilt_matrix("-118,0,0")
    moved = [Frame(index=f.index, rgb=f.rgb, depth=f.depth, K=K, T_wc=W @ f.T_wc, timestamp=f.timestamp)
             for f in frames]
    write_tum(moved, K, tmp_path / "rec")
    res = CliRunner().invoke(app, ["import", "auto", str(tmp_path / "rec"), "-o", str(tmp_path / "ds"),
                                   "--no-progress"])
    assert res.exit_code == 0, res.output + repr(res.exception)
    assert "floor confidence" in res.output and "runner-up plane +0.75 m above the floor" in res.output
    ds = DatasetReader(tmp_path / "ds")
    assert np.median(ds.poses[:, 2, 3]) == pytest.approx(1.35, abs=0.03)
