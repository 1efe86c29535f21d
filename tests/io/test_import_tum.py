"""TUM RGB-D import: simulator frames written in TUM layout in a y-down world with the floor at y = 1.3 m
come back as the original z-up poses; association, interpolation, skip reports and errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from scipy.spatial.transform import Rotation
from typer.testing import CliRunner

from capnav.cli import app
from capnav.core.errors import InputError, PoseError
from capnav.core.frame import Frame
from capnav.io.assoc import PoseTrack, match_nearest
from capnav.io.dataset import DatasetReader
from capnav.io.importer import import_recording
from capnav.io.tum import TumReader

# the recording's world: CapNav's +z is its -y (x axis turned +90 degrees), floor at y = +1.3 m
W = np.eye(4)
W[:3, :3] = Rotation.from_euler("x", 90, degrees=True).as_matrix()
W[:3, 3] = [0.0, 1.3, 0.0]
T0 = 1305031102.0  # TUM-like stamps: large numbers, so float parsing precision matters


@pytest.fixture(scope="module")
def frames(render_views) -> list[Frame]:  # type: ignore[no-untyped-def]
    return render_views(3, [20.0 + 3 * i for i in range(6)])


def _line(t: float, T: np.ndarray) -> str:
    q = Rotation.from_matrix(T[:3, :3]).as_quat()  # x y z w, as TUM
    return f"{t:.6f} " + " ".join(f"{v:.7f}" for v in (*T[:3, 3], *q))


def write_tum(root: Path, frames: list[Frame], depth_lag: dict[int, float] | None = None,
              gt_end: int | None = None, world: np.ndarray = W) -> list[float]:
    """Write ``frames`` as a TUM sequence in the recording world ``world`` (CapNav's world in it);
    colour stamps are returned. Ground truth comes as two poses 10 ms either side of each frame,
    turned +-3 degrees and moved +-2 cm, so only interpolation recovers the pose at the frame's stamp."""
    (root / "rgb").mkdir(parents=True)
    (root / "depth").mkdir()
    rgb_lines, dep_lines, gt_lines = ["# color images", "# timestamp filename"], ["# depth maps"], ["# ground truth"]
    stamps = []
    for i, f in enumerate(frames):
        t = T0 + 0.1 * i
        td = t + (depth_lag or {}).get(i, 0.004)
        stamps.append(t)
        Image.fromarray(f.rgb).save(root / "rgb" / f"{t:.6f}.png")
        d = np.where(f.valid_depth() & (f.depth * 5000 < 65535), np.round(f.depth * 5000), 0).astype(np.uint16)
        Image.fromarray(d).save(root / "depth" / f"{td:.6f}.png")
        rgb_lines.append(f"{t:.6f} rgb/{t:.6f}.png")
        dep_lines.append(f"{td:.6f} depth/{td:.6f}.png")
        if gt_end is not None and i >= gt_end:
            continue
        T = world @ f.T_wc
        for s in (-1.0, 1.0):
            D = np.eye(4)
            D[:3, :3] = Rotation.from_rotvec(s * np.radians(3.0) * np.array([0.3, 0.9, 0.3])).as_matrix()
            D[:3, 3] = s * np.array([0.02, -0.01, 0.015])
            gt_lines.append(_line(t + 0.01 * s, T @ D))
    for name, lines in (("rgb.txt", rgb_lines), ("depth.txt", dep_lines), ("groundtruth.txt", gt_lines)):
        (root / name).write_text("\n".join(lines) + "\n")
    (root / "cam.json").write_text(json.dumps(frames[0].K.to_dict()))
    return stamps


def _pose_err(A: np.ndarray, B: np.ndarray) -> tuple[float, float]:
    dt = float(np.linalg.norm(A[:3, 3] - B[:3, 3]))
    c = (np.trace(A[:3, :3].T @ B[:3, :3]) - 1) / 2
    return dt, float(np.degrees(np.arccos(np.clip(c, -1, 1))))


def test_round_trip_aligned(tmp_path: Path, frames: list[Frame]) -> None:
    write_tum(tmp_path / "seq", frames, depth_lag={4: 0.05})  # frame 4: depth 50 ms late -> skipped
    rec = TumReader(tmp_path / "seq", tmp_path / "seq" / "cam.json")
    assert rec.K == frames[0].K and len(rec.frames) == 5
    assert rec.skipped.counts() == {"no depth within max-dt 0.02 s": 1}
    assert rec.skipped.skips[0].name == f"rgb/{T0 + 0.4:.6f}.png" and "50 ms" in rec.skipped.skips[0].detail
    report = import_recording(rec, tmp_path / "ds", up="-y", progress=False)
    assert report.written == 5 and report.alignment.info["method"] == "floor-named"
    ds = DatasetReader(tmp_path / "ds")
    assert len(ds) == 5 and ds.intrinsics == frames[0].K and ds.has_gt is False
    assert ds.meta["meta"]["import"]["skipped"] == {"no depth within max-dt 0.02 s": 1}
    assert len(ds.meta["meta"]["alignment"]["A"]) == 16
    for g, orig in zip(ds, [f for i, f in enumerate(frames) if i != 4], strict=True):
        dt, dr = _pose_err(g.T_wc, orig.T_wc)
        assert dt < 0.01 and dr < 1.0, (g.index, dt, dr)
        assert np.array_equal(g.rgb, orig.rgb)
        ok = orig.valid_depth()
        assert np.array_equal(g.depth > 0, ok)
        assert np.abs(g.depth[ok] - orig.depth[ok]).max() < 0.0006  # 0.2 mm TUM units, then 1 mm dataset units
        assert abs(g.timestamp - (T0 + 0.1 * orig.index)) < 1e-6


def test_up_none_keeps_recording_frame(tmp_path: Path, frames: list[Frame]) -> None:
    write_tum(tmp_path / "seq", frames[:2])
    import_recording(TumReader(tmp_path / "seq", tmp_path / "seq" / "cam.json"), tmp_path / "ds", up="none",
                     progress=False)
    for g, orig in zip(DatasetReader(tmp_path / "ds"), frames[:2], strict=True):
        dt, dr = _pose_err(g.T_wc, W @ orig.T_wc)
        assert dt < 1e-4 and dr < 0.01


def test_no_pose_and_stride(tmp_path: Path, frames: list[Frame]) -> None:
    write_tum(tmp_path / "seq", frames, gt_end=4)  # ground truth stops after frame 3 (at +0.31 s)
    with pytest.raises(InputError, match=r"intrinsics \(fr1\) are for 640x480 but the colour image .* is 160x120"):
        TumReader(tmp_path / "seq", "fr1")  # the preset is another camera's: refused before anything is read
    rec = TumReader(tmp_path / "seq")  # cam.json beside rgb.txt is read by default
    assert rec.meta["intrinsics_source"].endswith("cam.json")
    assert rec.skipped.counts() == {"no pose": 2}
    assert "outside the pose stamps" in rec.skipped.skips[0].detail
    rep = import_recording(rec, tmp_path / "ds", up="-y", stride=2, max_frames=1, progress=False)
    assert rep.selected == 1 and len(DatasetReader(tmp_path / "ds")) == 1


def test_interpolation_and_association_units() -> None:
    Ts = np.tile(np.eye(4), (2, 1, 1))
    Ts[1, :3, :3] = Rotation.from_euler("z", 90, degrees=True).as_matrix()
    Ts[1, :3, 3] = [2.0, 0.0, 0.0]
    track = PoseTrack(np.array([10.0, 11.0]), Ts, "test")
    P, ok, why = track.at(np.array([10.25, 9.99, 9.0, 11.5]), max_dt=0.02, max_gap=2.0)
    assert ok.tolist() == [True, True, False, False] and why[2].startswith("outside")
    assert np.allclose(P[0, :3, 3], [0.5, 0, 0])
    assert np.isclose(Rotation.from_matrix(P[0, :3, :3]).as_euler("xyz", degrees=True)[2], 22.5)
    _, ok, why = track.at(np.array([10.5]), max_dt=0.02, max_gap=0.5)
    assert not ok[0] and "1.00 s apart" in why[0]
    idx, _ = match_nearest(np.array([0.0, 0.033, 0.066, 0.1]), np.array([0.001, 0.07, 0.5]), 0.02)
    assert idx.tolist() == [0, -1, 1, -1]


def test_errors_name_the_file_and_line(tmp_path: Path, frames: list[Frame]) -> None:
    seq = tmp_path / "seq"
    write_tum(seq, frames[:2])
    cam = (seq / "cam.json").rename(tmp_path / "cam.json")
    with pytest.raises(InputError, match="cannot tell the camera"):
        TumReader(seq)
    gt = (seq / "groundtruth.txt").read_text()
    (seq / "groundtruth.txt").write_text(gt + "1305031102.5 1 2 3 0 0 0\n")
    with pytest.raises(InputError, match=r"groundtruth.txt line 6: expected 8 fields"):
        TumReader(seq, cam)
    (seq / "groundtruth.txt").write_text(gt + "1305031102.5 1 2 3 0 0 0 2\n")
    with pytest.raises(PoseError, match=r"groundtruth.txt line 6: not a rigid pose: quaternion norm 2"):
        TumReader(seq, cam)
    (seq / "groundtruth.txt").write_text(gt.replace("1305031102.0", "13050311O2.0", 1))
    with pytest.raises(InputError, match="not a number"):
        TumReader(seq, cam)
    (seq / "groundtruth.txt").write_text(gt)
    next((seq / "depth").iterdir()).unlink()
    with pytest.raises(InputError, match=r"1 listed images are missing, e.g. .*depth/"):
        TumReader(seq, cam)
    (seq / "depth.txt").unlink()
    with pytest.raises(InputError, match=r"missing depth list file: .*depth.txt"):
        TumReader(seq, cam)
    with pytest.raises(InputError, match="not found"):
        TumReader(tmp_path / "nope", "fr1")


def test_a_corrupt_image_costs_its_frame_and_only_unreadable_images_leave_nothing(
        tmp_path: Path, frames: list[Frame]) -> None:
    seq = tmp_path / "seq"
    write_tum(seq, frames[:3])
    rgbs = sorted((seq / "rgb").iterdir())
    rgbs[2].write_bytes(b"\x89PNG not really")
    rep = import_recording(TumReader(seq, seq / "cam.json"), tmp_path / "ds", up="-y", progress=False)
    assert len(DatasetReader(tmp_path / "ds")) == 2
    text = "\n".join(rep.lines())
    assert "skipped 1: unreadable image" in text and rgbs[2].name in text
    for p in rgbs[:2]:
        p.write_bytes(b"")
    with pytest.raises(InputError, match="every selected frame was skipped"):
        import_recording(TumReader(seq, seq / "cam.json"), tmp_path / "ds2", up="-y", progress=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ds", "seq"]


def test_cli(tmp_path: Path, frames: list[Frame]) -> None:
    seq = tmp_path / "rgbd_dataset_freiburg1_sim"
    write_tum(seq, frames[:4], depth_lag={1: -0.03})
    args = ["import", "tum", str(seq), "-o", str(tmp_path / "ds"), "--intrinsics", str(seq / "cam.json"),
            "--no-progress"]
    res = CliRunner().invoke(app, args)  # no --up: found from the floor and the cameras
    assert res.exit_code == 0, res.output
    assert "3 frames written" in res.output and "skipped 1: no depth within max-dt" in res.output
    assert "up found: the recording's" in res.output and "deg from -y; confidence" in res.output
    assert len(DatasetReader(tmp_path / "ds")) == 3
    res = CliRunner().invoke(app, args)  # existing dataset: refuse without --overwrite
    assert res.exit_code != 0 and "not empty" in str(res.exception)
    res = CliRunner().invoke(app, [*args, "--overwrite", "--max-frames", "2"])
    assert res.exit_code == 0, res.output
    assert len(DatasetReader(tmp_path / "ds")) == 2
    res = CliRunner().invoke(app, [*args, "--overwrite", "--up", "+z"])  # the floor is the recording's -y
    assert res.exit_code != 0 and "--up +z contradicts the recording" in str(res.exception)
    assert len(DatasetReader(tmp_path / "ds")) == 2  # the dataset already there is kept
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_negative_max_pose_gap_is_refused(tmp_path: Path, frames: list[Frame]) -> None:
    write_tum(tmp_path / "seq", frames[:2])
    for bad in (-0.5, float("nan")):
        with pytest.raises(InputError, match=r"--max-pose-gap must be a number of seconds >= 0"):
            TumReader(tmp_path / "seq", max_pose_gap=bad)
    res = CliRunner().invoke(app, ["import", "tum", str(tmp_path / "seq"), "-o", str(tmp_path / "ds"),
                                   "--max-pose-gap", "-1", "--no-progress"])
    assert res.exit_code == 2 and "--max-pose-gap" in res.output and "give a number >= 0" in res.output
