"""Frame-per-file layouts (Open3D, 3DMatch, ScanNet) and ``capnav import auto``: simulator frames
written in each layout, in a recording world whose up is not +z, come back as the original z-up
poses with the frames in source order; each layout's bad input is refused with its cause or counted."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from typer.testing import CliRunner

from capnav.cli import app
from capnav.core.errors import InputError
from capnav.core.frame import Frame
from capnav.io.dataset import DatasetReader
from capnav.io.export import tilt_matrix, writer
from capnav.io.importer import import_recording
from capnav.io.intrinsics import from_json
from capnav.io.layouts import detect, open_recording
from capnav.io.open3d_log import Open3dReader

# the recording's world: the first camera looks along +z with y down, as Open3D and TUM logs often are
W = tilt_matrix("90,0,0")
W[:3, 3] = [0.0, 1.2, 0.0]  # the floor at y = +1.2 m (horizontal offsets are kept as recorded)


@pytest.fixture(scope="module")
def frames(render_views) -> list[Frame]:  # type: ignore[no-untyped-def]
    return render_views(5, [18.0 + 4 * i for i in range(6)])


def export(layout: str, frames: list[Frame], root: Path) -> Path:
    moved = [Frame(index=f.index, rgb=f.rgb, depth=f.depth, K=f.K, T_wc=W @ f.T_wc, timestamp=f.timestamp)
             for f in frames]
    writer(layout)(moved, frames[0].K, root)
    return root


def _pose_err(A: np.ndarray, B: np.ndarray) -> tuple[float, float]:
    c = (np.trace(A[:3, :3].T @ B[:3, :3]) - 1) / 2
    return float(np.linalg.norm(A[:3, 3] - B[:3, 3])), float(np.degrees(np.arccos(np.clip(c, -1, 1))))


@pytest.mark.parametrize("layout", ["open3d", "3dmatch", "scannet", "tum"])
def test_auto_reads_every_exported_layout_back(tmp_path: Path, frames: list[Frame], layout: str) -> None:
    src = export(layout, frames, tmp_path / "rec")
    res = CliRunner().invoke(app, ["import", "auto", str(src), "-o", str(tmp_path / "ds"), "--no-progress"])
    assert res.exit_code == 0, res.output + repr(res.exception)
    assert f"{layout} layout" in res.output and "up found" in res.output
    ds = DatasetReader(tmp_path / "ds")
    assert len(ds) == len(frames)
    assert np.allclose(list(ds.intrinsics.to_dict().values()), list(frames[0].K.to_dict().values()), atol=1e-6)
    imp = ds.meta["meta"]["import"]
    assert [r[1] for r in imp["frames"]] == list(range(len(frames)))  # source order, source index kept
    for g, orig in zip(ds, frames, strict=True):
        dt, dr = _pose_err(g.T_wc, orig.T_wc)
        assert dt < 0.02 and dr < 1.0, (layout, g.index, dt, dr)  # the world's yaw is kept: compare directly
        ok = orig.valid_depth() & (orig.depth < 10)
        both = ok & (g.depth > 0)
        assert both.sum() > 0.95 * ok.sum()
        assert np.abs(g.depth[both] - orig.depth[both]).max() < 0.002
        if layout != "scannet":  # ScanNet's colour comes at another resolution and as JPEG
            assert np.array_equal(g.rgb, orig.rgb)
        else:
            assert np.abs(g.rgb.astype(int) - orig.rgb.astype(int)).mean() < 8


def test_open3d_order_missing_poses_and_fit(tmp_path: Path, frames: list[Frame]) -> None:
    src = export("open3d", frames, tmp_path / "rec")
    log = (src / "trajectory.log").read_text().splitlines()
    (src / "trajectory.log").write_text("\n".join(log[:20]) + "\n")  # 4 poses for 6 images
    rec = Open3dReader(src)
    assert [f.source_index for f in rec.frames] == [0, 1, 2, 3]
    assert rec.skipped.counts() == {"no pose": 2}
    assert "4 poses for 6 images" in rec.skipped.skips[0].detail and rec.skipped.skips[0].name == "00004.png"
    rep = import_recording(rec, tmp_path / "ds", progress=False)
    assert rep.written == 4 and "skipped 2: no pose" in "\n".join(rep.lines())
    (src / "trajectory.log").unlink()
    with pytest.raises(InputError, match=r"missing pose file: .*trajectory.log"):
        Open3dReader(src)
    (src / "trajectory.log").write_text("\n".join(log) + "\n")
    K = frames[0].K
    (src / "camera_intrinsic.json").write_text(json.dumps({"width": 640, "height": 480, "intrinsic_matrix": [
        525.0, 0, 0, 0, 525.0, 0, 319.5, 239.5, 1]}))
    with pytest.raises(InputError, match=r"are for 640x480 but the depth image .* is 160x120"):
        Open3dReader(src)
    (src / "camera_intrinsic.json").write_text(json.dumps({"width": K.width, "height": K.height,
                                                           "intrinsic_matrix": [K.fx, 0, 0, 0, K.fy, 0, 300, 200, 1]}))
    with pytest.raises(InputError, match=r"principal point at \(300, 200\), outside the 160x120 image"):
        Open3dReader(src)


def test_log_entries_name_their_frames(tmp_path: Path, frames: list[Frame]) -> None:
    """A log that skipped a frame (its "i j k" lines say which) pairs each pose with its own image."""
    src = export("open3d", frames, tmp_path / "rec")
    blocks = (src / "trajectory.log").read_text().splitlines()
    (src / "trajectory.log").write_text("\n".join(blocks[:10] + blocks[15:]) + "\n")  # no entry for frame 2
    rec = Open3dReader(src)
    assert [f.source_index for f in rec.frames] == [0, 1, 3, 4, 5]
    assert np.allclose(rec.frames[2].T_wc, W @ frames[3].T_wc, atol=1e-6)


def test_intrinsics_json_both_orders() -> None:
    col = from_json({"width": 640, "height": 480, "intrinsic_matrix": [500, 0, 0, 0, 501, 0, 320, 240, 1]}, "x", None)
    row = from_json({"width": 640, "height": 480, "intrinsic_matrix": [500, 0, 320, 0, 501, 240, 0, 0, 1]}, "x", None)
    assert col == row and (col.fx, col.fy, col.cx, col.cy) == (500, 501, 320, 240)
    with pytest.raises(InputError, match="not a pinhole matrix"):
        from_json({"width": 1, "height": 1, "intrinsic_matrix": [1, 2, 3, 4, 5, 6, 7, 8, 9]}, "x", None)


def test_3dmatch_and_scannet_bad_input(tmp_path: Path, frames: list[Frame]) -> None:
    src = export("3dmatch", frames[:3], tmp_path / "m")
    (src / "seq-01" / "frame-000001.pose.txt").unlink()
    rec, lay, ev = open_recording(src)
    assert lay.name == "3dmatch" and "1 sequence folder" in ev
    assert rec.skipped.counts() == {"no pose": 1} and "missing pose file" in rec.skipped.skips[0].detail
    (src / "camera-intrinsics.txt").unlink()
    with pytest.raises(InputError, match=r"missing intrinsics file camera-intrinsics\.txt"):
        open_recording(src)
    src = export("scannet", frames[:3], tmp_path / "s")
    (src / "pose" / "1.txt").write_text("\n".join(["-inf -inf -inf -inf"] * 4) + "\n")  # tracking lost
    rec, lay, _ = open_recording(src)
    assert lay.name == "scannet" and rec.skipped.counts() == {"no pose": 1}
    assert "non-finite" in rec.skipped.skips[0].detail
    shutil.rmtree(src / "pose")
    (src / "pose").mkdir()
    with pytest.raises(InputError, match=r"no frame has both a depth image and a pose .*missing pose file"):
        open_recording(src)


def test_auto_names_what_it_looked_for(tmp_path: Path) -> None:
    (tmp_path / "x").mkdir()
    Image.fromarray(np.zeros((4, 4, 3), np.uint8)).save(tmp_path / "x" / "a.png")
    with pytest.raises(InputError, match=r"not a recording layout CapNav knows. Looked for .*open3d: image/"):
        detect(tmp_path / "x")
    (tmp_path / "x" / "meta.json").write_text('{"format": "capnav-rgbd"}')
    with pytest.raises(InputError, match=r"already a capnav-rgbd dataset .* map it directly"):
        open_recording(tmp_path / "x")
    (tmp_path / "x.bag").write_bytes(b"#ROSBAG V2.0\n")
    with pytest.raises(InputError, match=r"is a ROS bag .*capnav import rosbag .* --rgb-topic"):
        open_recording(tmp_path / "x.bag")


ICL = Path(__file__).resolve().parents[2].parent / "shared" / "realdata" / "icl-livingroom1"


@pytest.mark.skipif(not ICL.is_dir(), reason="needs ../shared/realdata/icl-livingroom1")
def test_icl_livingroom_imports_with_no_option(tmp_path: Path) -> None:
    """The real Open3D folder: up (the first camera's -y) found with no option, cameras about 1 m up."""
    res = CliRunner().invoke(app, ["import", "auto", str(ICL), "-o", str(tmp_path / "icl"), "--stride", "15",
                                   "--no-progress"])
    assert res.exit_code == 0, res.output + repr(res.exception)
    assert "open3d layout (image/, depth/, trajectory.log)" in res.output
    al = DatasetReader(tmp_path / "icl").meta["meta"]["alignment"]
    assert al["nearest_axis"] == "-y" and al["axis_angle_deg"] < 5
    assert 0.7 < al["facts"]["camera_height_median_m"] < 1.3


def test_depth_in_the_wrong_scale_warns(tmp_path: Path, frames: list[Frame]) -> None:
    """Millimetre PNGs read as TUM's 5000 per metre: the cameras come out 0.25 m above the floor."""
    src = export("open3d", frames, tmp_path / "rec")
    res = CliRunner().invoke(app, ["import", "open3d", str(src), "-o", str(tmp_path / "ds"), "--depth-scale", "5000",
                                   "--no-progress"])
    assert res.exit_code == 0, res.output + repr(res.exception)
    assert "warning: the cameras are 0.25 m above the floor found" in res.output and "--depth-scale" in res.output


def test_depth_read_too_far_names_the_depth_scale(tmp_path: Path, frames: list[Frame]) -> None:
    """Millimetre PNGs read at 200 units per metre: every depth 5x too far, the cameras over 5 m above
    any floor; the refusal names the depth scale, not only --up."""
    src = export("open3d", frames, tmp_path / "rec")
    res = CliRunner().invoke(app, ["import", "open3d", str(src), "-o", str(tmp_path / "ds"), "--depth-scale", "200",
                                   "--no-progress"])
    assert res.exit_code != 0
    assert "is the depth scale right (--depth-scale" in res.output + str(res.exception), res.output


@pytest.fixture(scope="module")
def walk() -> list[Frame]:
    """Eight neighbouring views: a camera 1.25 m up, pitched 20 deg, stepping 8 cm and turning 3 deg a frame."""
    import math

    from capnav.core.geometry import look_at_pose
    from capnav.sim import CameraConfig, LayoutConfig, SimConfig, Simulator

    sim = Simulator.from_seed(0, SimConfig(layout=LayoutConfig(rooms=3), camera=CameraConfig(width=160, height=120)))
    try:
        x, y = sim.random_navigable_point(np.random.default_rng(2))
        return [sim.render(look_at_pose(np.array([x + 0.08 * i, y + 0.03 * i, 1.25]), math.radians(40 + 3 * i),
                                        math.radians(20)), index=i) for i in range(8)]
    finally:
        sim.close()


@pytest.mark.parametrize("how,says", [
    ("inverse", "the poses are world-to-camera"), ("gl", "OpenGL camera axes"), ("scale", "5 times too big")])
def test_a_wrong_convention_is_refused_with_the_reason(tmp_path: Path, walk: list[Frame], how: str,
                                                       says: str) -> None:
    GL = np.diag([1.0, -1.0, -1.0, 1.0])
    src = export("open3d", walk, tmp_path / "rec")
    args = ["import", "auto", str(src), "-o", str(tmp_path / "ds"), "--no-progress"]
    res = CliRunner().invoke(app, args)
    assert res.exit_code == 0 and "poses checked against depth" in res.output, res.output
    poses = [W @ f.T_wc for f in walk]
    if how == "inverse":
        poses = [np.linalg.inv(T) for T in poses]
    elif how == "gl":
        poses = [T @ GL for T in poses]
    else:
        args += ["--depth-scale", "5000"]
    from capnav.io.open3d_log import log_text

    (src / "trajectory.log").write_text(log_text(poses))
    res = CliRunner().invoke(app, [*args, "--overwrite"])
    assert res.exit_code != 0 and isinstance(res.exception, InputError)
    msg = str(res.exception)
    assert "do not fit together as read" in msg and says in msg and "as recorded" in msg, msg


@pytest.mark.parametrize(("present", "layout", "missing"), [
    (("image/", "depth/"), "open3d", "trajectory.log"),
    (("color/", "depth/", "pose/"), "scannet", "intrinsic/"),
    (("rgb.txt",), "tum", "depth.txt"),
    (("odometry.csv", "depth/"), "stray", "camera_matrix.csv"),
])
def test_auto_names_the_missing_part_of_the_nearest_layout(tmp_path: Path, present: tuple[str, ...],
                                                           layout: str, missing: str) -> None:
    """A folder holding most of one layout is told which of that layout's files it lacks, not the list
    of every layout (a recording copied without its trajectory is the usual case)."""
    src = tmp_path / "rec"
    src.mkdir()
    for p in present:
        (src / p.rstrip("/")).mkdir() if p.endswith("/") else (src / p).write_text("# x\n")
    want = rf"looks like the {layout} layout \(has .*\) but {re.escape(missing)} is missing"
    with pytest.raises(InputError, match=want) as e:
        detect(src)
    assert "Looked for" not in str(e.value)
