"""Dataset folder format: round trip, atomic/complete marker, and errors that name the frame."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from capnav.core.errors import DatasetError, FrameError, PoseError
from capnav.core.frame import Frame
from capnav.core.geometry import Intrinsics, look_at_pose
from capnav.io.dataset import DatasetReader, DatasetWriter

K = Intrinsics.from_fov(32, 24, 60.0)


def _frames(n: int, gt: bool = True) -> list[Frame]:
    rng = np.random.default_rng(0)
    out = []
    for i in range(n):
        depth = rng.uniform(0.3, 9.0, (24, 32)).astype(np.float32)
        depth[0, :3] = [0.0, np.nan, np.inf]  # invalid pixels stay invalid (0)
        out.append(Frame(index=i, rgb=rng.integers(0, 256, (24, 32, 3), dtype=np.uint8), depth=depth, K=K,
                         T_wc=look_at_pose(rng.uniform(-3, 3, 3), float(rng.uniform(-3, 3)), 0.2), timestamp=0.1 * i,
                         gt_instance=rng.integers(0, 40, (24, 32)).astype(np.int32) if gt else None,
                         gt_category=rng.integers(0, 25, (24, 32)).astype(np.int32) if gt else None))
    return out


def _write(path: Path, frames: list[Frame]) -> None:
    with DatasetWriter(path, K, {"seed": 3, "note": "test"}) as w:
        for f in frames:
            w.write(f)


def test_round_trip(tmp_path: Path) -> None:
    frames = _frames(5)
    _write(tmp_path / "ds", frames)
    r = DatasetReader(tmp_path / "ds")
    assert len(r) == 5 and r.intrinsics == K and r.meta["meta"] == {"seed": 3, "note": "test"}
    assert r.manifest_path is None
    for a, b in zip(frames, r, strict=True):
        assert np.array_equal(a.rgb, b.rgb)
        valid = np.isfinite(a.depth) & (a.depth > 0)
        assert np.all(b.depth[~valid] == 0)
        assert np.abs(a.depth[valid] - b.depth[valid]).max() <= 0.0005 + 1e-6  # millimetre PNG
        assert np.array_equal(a.T_wc, b.T_wc)  # poses are stored exactly (repr of float64)
        assert b.timestamp == a.timestamp
        assert np.array_equal(a.gt_instance, b.gt_instance) and np.array_equal(a.gt_category, b.gt_category)
        assert b.K == K


def test_without_ground_truth(tmp_path: Path) -> None:
    _write(tmp_path / "ds", _frames(2, gt=False))
    f = DatasetReader(tmp_path / "ds").frame(1)
    assert f.gt_instance is None and f.gt_category is None


def test_missing_and_corrupt_frames_are_named(tmp_path: Path) -> None:
    _write(tmp_path / "ds", _frames(4))
    (tmp_path / "ds" / "depth" / "000002.png").unlink()
    r = DatasetReader(tmp_path / "ds")
    r.frame(1)
    with pytest.raises(DatasetError, match=r"frame 2: missing .*depth/000002.png") as e:
        r.frame(2)
    assert isinstance(e.value, FrameError) and e.value.frame == 2
    (tmp_path / "ds" / "rgb" / "000003.png").write_bytes(b"\x89PNG garbage")
    with pytest.raises(DatasetError, match=r"frame 3: corrupt .*rgb/000003.png"):
        r.frame(3)
    with pytest.raises(DatasetError, match="frame 2"):
        list(r)
    with pytest.raises(DatasetError, match="out of range"):
        r.frame(9)


def test_wrong_size_frame_and_bad_pose_are_named(tmp_path: Path) -> None:
    _write(tmp_path / "ds", _frames(3))
    from PIL import Image

    Image.fromarray(np.zeros((10, 10, 3), np.uint8)).save(tmp_path / "ds" / "rgb" / "000001.png")
    with pytest.raises(DatasetError, match=r"frame 1: .*10x10, expected 32x24"):
        DatasetReader(tmp_path / "ds").frame(1)
    lines = (tmp_path / "ds" / "poses.txt").read_text().splitlines()
    vals = lines[2].split()
    vals[2] = "-1.0"  # breaks the rotation's orthonormality
    lines[2] = " ".join(vals)
    (tmp_path / "ds" / "poses.txt").write_text("\n".join(lines) + "\n")
    r = DatasetReader(tmp_path / "ds")  # one bad pose costs its frame, not the dataset
    with pytest.raises(DatasetError, match=r"frame 2: .*line 3: rotation is not orthonormal"):
        r.frame(2)
    assert r.frame(0).index == 0 and list(r.bad_poses) == [2]


def test_incomplete_and_malformed_datasets(tmp_path: Path) -> None:
    w = DatasetWriter(tmp_path / "ds", K)
    for f in _frames(30):
        w.write(f)
    # not closed: the reader refuses unless asked, then sees the flushed frames
    with pytest.raises(DatasetError, match="incomplete"):
        DatasetReader(tmp_path / "ds")
    assert len(DatasetReader(tmp_path / "ds", allow_incomplete=True)) == 25
    w.close()
    assert len(DatasetReader(tmp_path / "ds")) == 30
    with pytest.raises(DatasetError, match="not empty"):
        DatasetWriter(tmp_path / "ds", K)
    with pytest.raises(DatasetError, match="not found"):
        DatasetReader(tmp_path / "nope")
    meta = json.loads((tmp_path / "ds" / "meta.json").read_text())
    meta["version"] = 7
    (tmp_path / "ds" / "meta.json").write_text(json.dumps(meta))
    with pytest.raises(DatasetError, match="version 7"):
        DatasetReader(tmp_path / "ds")
    (tmp_path / "ds" / "intrinsics.json").unlink()
    meta["version"] = 1
    (tmp_path / "ds" / "meta.json").write_text(json.dumps(meta))
    with pytest.raises(DatasetError, match=r"missing intrinsics\.json"):
        DatasetReader(tmp_path / "ds")


def test_overwrite_replaces_previous_frames(tmp_path: Path) -> None:
    _write(tmp_path / "ds", _frames(4))
    with DatasetWriter(tmp_path / "ds", K, overwrite=True) as w:
        w.write(_frames(1)[0])
    assert len(DatasetReader(tmp_path / "ds")) == 1
    assert not (tmp_path / "ds" / "rgb" / "000003.png").exists()


def test_writer_rejects_mismatched_frames(tmp_path: Path) -> None:
    with DatasetWriter(tmp_path / "ds", K) as w:
        f = _frames(1)[0]
        other = Frame(0, np.zeros((12, 16, 3), np.uint8), np.ones((12, 16), np.float32), K.scaled(16, 12), f.T_wc)
        with pytest.raises(FrameError):
            w.write(other)
        bad = _frames(1)[0]
        bad.T_wc = np.diag([1.0, 1.0, -1.0, 1.0])
        with pytest.raises(PoseError):
            w.write(bad)
        w.write(f)
        with pytest.raises(FrameError, match=r"every frame or in none"):
            w.write(_frames(1, gt=False)[0])
