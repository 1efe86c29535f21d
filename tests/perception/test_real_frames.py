"""Real pixels end to end: depth of the TUM, NYU and SUN frames in ../shared/realdata decoded to
metres, a real detector's chair lifted to 3D, and a one-frame map (identity pose, PrimeSense
intrinsics, as ../shared/realdata/README.md says) built by ``capnav map --detector yolo-fastest``
holding a chair where the frame's pixels put it."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from capnav.cli import app
from capnav.core.categories import category
from capnav.core.errors import InputError
from capnav.core.frame import Frame
from capnav.core.geometry import Intrinsics
from capnav.io.dataset import DatasetWriter
from capnav.io.depth_formats import decode_depth
from capnav.io.mapfile import load_map
from capnav.io.tum import read_rgb
from capnav.mapping import Mapper, MapperConfig
from capnav.mapping.lifting import LiftConfig, lift_detection
from capnav.mapping.tracker import TrackerConfig
from capnav.perception import create_detector, create_encoder

PRIMESENSE = Intrinsics(525.0, 525.0, 319.5, 239.5, 640, 480)
FILES = {"tum": ("TUM_color.png", "TUM_depth.png"), "nyu": ("NYU_color.ppm", "NYU_depth.pgm"),
         "sun": ("SUN_color.jpg", "SUN_depth.png")}


@pytest.fixture(scope="module")
def real(shared_dir: Path) -> Path:
    return shared_dir / "realdata"


def _frame(real: Path, enc: str) -> Frame:
    rgb_name, depth_name = FILES[enc]
    return Frame(0, read_rgb(real / rgb_name), decode_depth(real / depth_name, enc), PRIMESENSE, np.eye(4))


@pytest.mark.parametrize("enc", sorted(FILES))
def test_depth_decoding_is_plausible(enc: str, real: Path) -> None:
    f = _frame(real, enc)
    d = f.depth
    assert d.shape == (480, 640) and d.dtype == np.float32 and f.rgb.shape == (480, 640, 3)
    valid = d > 0
    assert np.isfinite(d).all() and valid.mean() > 0.75  # rooms seen by a Kinect: mostly valid
    lo, med, hi = np.percentile(d[valid], [1, 50, 99])
    assert 0.3 <= lo and 1.0 < med < 5.0 and hi < 10.0  # indoor distances in metres, not mm or raw units
    # depth is smooth: most neighbouring valid pixels differ by a few cm, not by wrapped bits
    both = valid[:, 1:] & valid[:, :-1]
    step = np.abs(np.diff(d, axis=1))[both]
    assert np.median(step) < 0.02


def test_wrong_interpretations_are_implausible(real: Path) -> None:
    """The named encoding matters: the SUN file read as TUM or the NYU bytes read big-endian are garbage."""
    as_tum = decode_depth(real / "SUN_depth.png", "tum", scale=1000.0)
    assert np.median(as_tum[as_tum > 0]) > 10.0  # the millimetres shifted 3 bits up: 8x too far
    raw = np.frombuffer((real / "NYU_depth.pgm").read_bytes()[-640 * 480 * 2:], dtype=">u2")
    assert ((raw > 0) & (raw < 1084)).mean() < 0.1


def test_depth_errors(real: Path, tmp_path: Path) -> None:
    with pytest.raises(InputError, match="unknown depth encoding"):
        decode_depth(real / "TUM_depth.png", "kinect")
    with pytest.raises(InputError, match="8-bit"):
        (tmp_path / "a.pgm").write_bytes(b"P5 2 2 255\n" + bytes(4))
        decode_depth(tmp_path / "a.pgm", "nyu")
    data = (real / "NYU_depth.pgm").read_bytes()
    (tmp_path / "t.pgm").write_bytes(data[: len(data) // 2])
    with pytest.raises(InputError, match="truncated"):
        decode_depth(tmp_path / "t.pgm", "nyu")
    with pytest.raises(InputError, match="16-bit grey"):
        decode_depth(real / "SUN_color.jpg", "sun")
    with pytest.raises(InputError, match="missing"):
        decode_depth(tmp_path / "none.png", "tum")


def _expected_point(frame: Frame, box: tuple[float, float, float, float]) -> np.ndarray:
    """Where the box's pixels put the object: its centre pixel at the nearest depth mode of the middle
    of the box (the chair, not the floor or wall around it), back-projected with the intrinsics."""
    x0, y0, x1, y1 = box
    u, v = (x0 + x1) / 2, (y0 + y1) / 2
    win = frame.depth[int(v - (y1 - y0) / 6): int(v + (y1 - y0) / 6), int(u - (x1 - x0) / 6): int(u + (x1 - x0) / 6)]
    z = float(np.percentile(win[win > 0], 25))
    K = frame.K
    return np.array([(u - K.cx) / K.fx * z, (v - K.cy) / K.fy * z, z])


def test_lifting_a_real_chair(real: Path, shared_dir: Path) -> None:
    frame = _frame(real, "tum")
    det = create_detector("yolo-fastest", model_dir=str(shared_dir / "weights" / "yolo-fastest-1.1-xl"), threads=1)
    dets = det.detect(frame)
    chairs = [d for d in dets if d.label == "chair"]
    assert chairs
    from _synth_scene import HashEmbedder

    enc = create_encoder("label-embedding", embedder=HashEmbedder())
    grid, table = enc.encode_indexed(frame, dets)
    # Both the solid office chair and the open-frame yellow chair on one post lift onto themselves:
    # the depth mask keeps the chair, not the floor and desk seen through its frame.
    for d in chairs:
        ld = lift_detection(frame, d, dets.index(d), grid, table, LiftConfig())
        assert ld is not None
        want = _expected_point(frame, d.box)
        assert np.linalg.norm(ld.position - want) < 0.3, (d.box, ld.position, want)
        assert 0.5 < ld.distance < 4.0 and len(ld.points) > 50
        extent = ld.points.max(axis=0) - ld.points.min(axis=0)
        assert extent[0] < 1.5  # one chair wide, not the desk or the wall behind it


def _big_chair_point(frame: Frame, folder: Path) -> np.ndarray:
    det = create_detector("yolo-fastest", model_dir=str(folder), threads=1)
    big = max((d for d in det.detect(frame) if d.label == "chair"),
              key=lambda d: (d.box[2] - d.box[0]) * (d.box[3] - d.box[1]))
    return _expected_point(frame, big.box)


def test_one_frame_map_has_the_chair(real: Path, shared_dir: Path) -> None:
    from _synth_scene import HashEmbedder

    frame = _frame(real, "tum")
    folder = shared_dir / "weights" / "yolo-fastest-1.1-xl"
    det = create_detector("yolo-fastest", model_dir=str(folder), threads=1)
    cfg = MapperConfig(tracker=TrackerConfig(h_min=1))  # one frame: every detection is its only sighting
    m = Mapper(cfg, det, create_encoder("label-embedding", embedder=HashEmbedder()))
    assert m.integrate(frame)
    cmap = m.finish()
    assert len(cmap.voxels) > 5000 and cmap.occupancy is not None
    chairs = [o for o in cmap.objects if o.label == "chair" and o.category_id == category("chair").id]
    assert chairs, [o.label for o in cmap.objects]
    want = _big_chair_point(frame, folder)
    assert min(float(np.linalg.norm(np.asarray(o.position) - want)) for o in chairs) < 0.3
    assert {"bottle", "book"} & {o.label for o in cmap.objects}  # small things on the desk, under their COCO names


def test_capnav_map_on_a_still_real_camera(real: Path, shared_dir: Path, tmp_path: Path) -> None:
    """``capnav map --detector yolo-fastest`` end to end on a camera standing still for 3 frames."""
    frame = _frame(real, "tum")
    ds = tmp_path / "tum3"
    with DatasetWriter(ds, PRIMESENSE) as w:
        for k in range(3):
            w.write(dataclasses.replace(frame, index=k, timestamp=k / 30))
    out = tmp_path / "tum3.capnav"
    folder = shared_dir / "weights" / "yolo-fastest-1.1-xl"
    r = CliRunner().invoke(app, ["map", str(ds), "-o", str(out), "--detector", "yolo-fastest", "--no-progress",
                                 "--detector-option", f"model_dir={folder}", "--detector-option", "threads=1"])
    assert r.exit_code == 0, r.output
    assert "nan" not in r.output and "3 frames" in r.output and "warning" not in r.output
    cmap = load_map(out)
    assert cmap.meta["detector"].startswith("yolo-fastest:yolo-fastest-1.1-xl:")
    chairs = [o for o in cmap.objects if o.label == "chair"]
    want = _big_chair_point(frame, folder)
    assert chairs and min(float(np.linalg.norm(np.asarray(o.position) - want)) for o in chairs) < 0.3
    # the same frames without truth images: the sim detector is refused at once, naming the real ones
    r = CliRunner().invoke(app, ["map", str(ds), "-o", str(tmp_path / "x.capnav"), "--no-progress"])
    assert isinstance(r.exception, InputError)
    assert "no simulator truth images" in str(r.exception) and "yolo-fastest" in str(r.exception)
    assert not (tmp_path / "x.capnav").exists()


def test_capnav_map_says_why_a_map_is_empty(real: Path, shared_dir: Path, tmp_path: Path) -> None:
    frame = _frame(real, "tum")
    ds = tmp_path / "tum4"
    with DatasetWriter(ds, PRIMESENSE) as w:
        for k in range(4):
            w.write(dataclasses.replace(frame, index=k, timestamp=k / 30))
    for k in (1, 2):
        (ds / "depth" / f"{k:06d}.png").unlink()
    folder = shared_dir / "weights" / "centernet-mobilenetv3-coco"
    r = CliRunner().invoke(app, ["map", str(ds), "-o", str(tmp_path / "e.capnav"), "--detector", "centernet",
                                 "--no-progress", "--detector-option", f"model_dir={folder}",
                                 "--detector-option", 'classes=["toilet"]'])
    assert r.exit_code == 0, r.output
    out = " ".join(r.output.split())
    assert "0 objects" in out and "nan" not in out
    assert "skipped 2 frames (first: 1): missing" in out and out.count("skipped") == 1  # one line per reason
    assert "warning: the map has 0 objects: the detector found nothing it keeps" in out


def test_sim_detector_is_refused_on_real_frames(real: Path) -> None:
    from _synth_scene import HashEmbedder

    m = Mapper(MapperConfig(), create_detector("sim"), create_encoder("label-embedding", embedder=HashEmbedder()))
    with pytest.raises(InputError, match=r"frame 0 has no simulator truth images .* centernet, owl or yolo-fastest"):
        m.integrate(_frame(real, "nyu"))
