"""Stray Scanner captures (the layout has no simulator export, so the test writes one): colour twice the
depth's size as rgb.mp4 (written with OpenCV, which reads it back) or as frames, LiDAR depth at half the
simulator's size with a confidence map, ARKit-like poses in a y-up world; read back z up at the
colour's field of view, low-confidence depth dropped."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from scipy.spatial.transform import Rotation
from typer.testing import CliRunner

from capnav.cli import app
from capnav.core.errors import InputError
from capnav.core.frame import Frame
from capnav.io.dataset import DatasetReader
from capnav.io.export import tilt_matrix
from capnav.io.stray import StrayReader

Y_UP = tilt_matrix("-90,0,0")  # CapNav's +z becomes the recording's +y, as ARKit's world


@pytest.fixture(scope="module")
def walk() -> list[Frame]:
    from capnav.core.geometry import look_at_pose
    from capnav.sim import CameraConfig, LayoutConfig, SimConfig, Simulator

    sim = Simulator.from_seed(0, SimConfig(layout=LayoutConfig(rooms=3), camera=CameraConfig(width=160, height=120)))
    try:
        x, y = sim.random_navigable_point(np.random.default_rng(7))
        return [sim.render(look_at_pose(np.array([x + 0.07 * i, y - 0.04 * i, 1.3]), math.radians(-30 + 4 * i),
                                        math.radians(25)), index=i) for i in range(7)]
    finally:
        sim.close()


def write_stray(root: Path, frames: list[Frame], video: bool) -> None:
    import cv2

    (root / "depth").mkdir(parents=True)
    (root / "confidence").mkdir()
    K = frames[0].K
    big = (2 * K.width, 2 * K.height)
    Kc = K.scaled(*big)
    (root / "camera_matrix.csv").write_text("\n".join(",".join(f"{v:.6f}" for v in row) for row in Kc.K) + "\n")
    lines = ["timestamp, frame, x, y, z, qx, qy, qz, qw"]
    if video:
        vw = cv2.VideoWriter(str(root / "rgb.mp4"), cv2.VideoWriter_fourcc(*"mp4v"), 30, big)
    else:
        (root / "rgb").mkdir()
    for i, f in enumerate(frames):
        rgb = np.asarray(Image.fromarray(f.rgb).resize(big, Image.Resampling.BICUBIC))
        if video:
            vw.write(np.ascontiguousarray(rgb[:, :, ::-1]))
        else:
            Image.fromarray(rgb).save(root / "rgb" / f"{i:06d}.png")
        d = np.where(f.valid_depth(), np.round(f.depth * 1000), 0).astype(np.uint16)[::2, ::2]  # 80x60 "LiDAR"
        conf = np.full(d.shape, 2, np.uint8)
        conf[:6] = 0  # the top rows are unsure
        Image.fromarray(d).save(root / "depth" / f"{i:06d}.png")
        Image.fromarray(conf).save(root / "confidence" / f"{i:06d}.png")
        T = Y_UP @ f.T_wc
        q = Rotation.from_matrix(T[:3, :3]).as_quat()
        lines.append(f"{100.0 + i / 60:.6f}, {i}, " + ", ".join(f"{v:.7f}" for v in (*T[:3, 3], *q)))
    if video:
        vw.release()
    (root / "odometry.csv").write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize("video", [True, False])
def test_stray_round_trip(tmp_path: Path, walk: list[Frame], video: bool) -> None:
    write_stray(tmp_path / "cap", walk, video)
    res = CliRunner().invoke(app, ["import", "auto", str(tmp_path / "cap"), "-o", str(tmp_path / "ds"),
                                   "--no-progress"])
    assert res.exit_code == 0, res.output + repr(res.exception)
    assert "stray layout" in res.output and "poses checked against depth" in res.output
    assert "up found: the recording's" in res.output and "deg from +y" in res.output
    ds = DatasetReader(tmp_path / "ds")
    assert len(ds) == len(walk) and (ds.intrinsics.width, ds.intrinsics.height) == (320, 240)
    assert ds.meta["meta"]["import"]["frames"][3][1] == 3
    for g, orig in zip(ds, walk, strict=True):
        assert abs(g.T_wc[2, 3] - 1.3) < 0.02
        assert np.allclose(np.linalg.inv(ds.poses[0]) @ g.T_wc, np.linalg.inv(walk[0].T_wc) @ orig.T_wc, atol=0.01)
        assert not (g.depth[:20] > 0).any()  # confidence-0 rows dropped (6 of 60 rows, about 24 of 240)
        small = np.asarray(Image.fromarray(g.rgb).resize((160, 120), Image.Resampling.BILINEAR), dtype=int)
        assert np.abs(small - orig.rgb.astype(int)).mean() < 12
        up = g.depth[::2, ::2][30:]
        ok = (up > 0) & orig.valid_depth()[30:]
        assert np.median(np.abs(up[ok] - orig.depth[30:][ok])) < 0.01


def test_stray_bad_input(tmp_path: Path, walk: list[Frame]) -> None:
    write_stray(tmp_path / "cap", walk[:3], video=False)
    odo = (tmp_path / "cap" / "odometry.csv").read_text().splitlines()
    (tmp_path / "cap" / "odometry.csv").write_text("\n".join(odo[:3]) + "\n")  # poses of frames 0 and 1 only
    rec = StrayReader(tmp_path / "cap")
    assert rec.skipped.counts() == {"no pose": 1} and "no line for frame 2" in rec.skipped.skips[0].detail
    (tmp_path / "cap" / "odometry.csv").write_text(odo[0] + "\n" + odo[1].replace(",", ";") + "\n")
    with pytest.raises(InputError, match=r"odometry.csv line 2: expected 9 comma-separated fields"):
        StrayReader(tmp_path / "cap")
    (tmp_path / "cap" / "odometry.csv").unlink()
    with pytest.raises(InputError, match=r"missing pose file: .*odometry.csv"):
        StrayReader(tmp_path / "cap")
