"""The COCO-80 detectors (yolo-fastest, centernet) on real pixels, from ../shared/weights.

The TUM desk frame shows two chairs, bottles and books (../shared/realdata/README.md); both
real models find the chairs and bottles there. The rest pins what the mapper relies on: valid
output, masks inside boxes, the COCO -> CapNav mapping, NMS per class, geometry of the resize,
and clear errors for a bad frame, a bad option or missing / corrupt weights.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from capnav.core.categories import category
from capnav.core.errors import FrameError, InputError, ModelError
from capnav.core.frame import Frame
from capnav.core.geometry import Intrinsics
from capnav.io.depth_formats import decode_depth
from capnav.io.tum import read_rgb
from capnav.perception import DETECTORS, create_detector, validate_detections
from capnav.perception.coco import COCO80, KEPT_AS_IS, TO_CAPNAV, class_table, coco_label
from capnav.perception.coco_detector import fit_to_square
from capnav.perception.nms import per_class_nms

BACKENDS = {"yolo-fastest": "yolo-fastest-1.1-xl", "centernet": "centernet-mobilenetv3-coco"}
PRIMESENSE = Intrinsics(525.0, 525.0, 319.5, 239.5, 640, 480)


@pytest.fixture(scope="module")
def tum_frame(shared_dir: Path) -> Frame:
    real = shared_dir / "realdata"
    return Frame(0, read_rgb(real / "TUM_color.png"), decode_depth(real / "TUM_depth.png", "tum"), PRIMESENSE,
                 np.eye(4))


@pytest.fixture(scope="module", params=sorted(BACKENDS))
def detector(request: pytest.FixtureRequest, shared_dir: Path):  # type: ignore[no-untyped-def]
    name = request.param
    return create_detector(name, model_dir=str(shared_dir / "weights" / BACKENDS[name]), threads=1)


def test_registered() -> None:
    assert {"yolo-fastest", "centernet"} <= set(DETECTORS.names())


def test_coco_mapping() -> None:
    assert len(COCO80) == 80 and len(set(COCO80)) == 80
    assert coco_label("couch") == (category("sofa").id, "sofa")
    assert coco_label("dining table") == (category("table").id, "table")
    assert coco_label("potted plant") == (category("plant").id, "plant")
    assert coco_label("oven") == (category("stove").id, "stove")
    assert coco_label("vase") == (0, "vase")
    for coco, capnav in TO_CAPNAV.items():
        assert coco in COCO80 and coco_label(coco)[1] == capnav
    indoor = class_table("indoor")
    kept = {COCO80[i] for i, t in enumerate(indoor) if t is not None}
    assert kept == set(TO_CAPNAV) | set(KEPT_AS_IS)
    assert "person" not in kept and "car" not in kept and {"book", "clock", "laptop", "bottle"} <= kept
    assert all(t is not None for t in class_table("all"))
    only = class_table(["chair", "vase"])
    assert [COCO80[i] for i, t in enumerate(only) if t is not None] == ["chair", "vase"]
    with pytest.raises(InputError, match="unknown"):
        class_table("chair,sofa")  # sofa is CapNav's name, not COCO's (couch)


@pytest.mark.parametrize("letterbox", [False, True])
def test_fit_to_square_round_trip(letterbox: bool) -> None:
    rgb = np.zeros((48, 96, 3), dtype=np.uint8)
    rgb[12:24, 30:60] = 255  # a white block: it must land where the inverse map says
    img, (sx, sy, px, py) = fit_to_square(rgb, 64, letterbox)
    assert img.shape == (64, 64, 3) and img.dtype == np.uint8
    ys, xs = np.nonzero(img[..., 0] > 128)
    x0, x1 = (xs.min() - px) / sx, (xs.max() + 1 - px) / sx
    y0, y1 = (ys.min() - py) / sy, (ys.max() + 1 - py) / sy
    assert (x0, y0, x1, y1) == pytest.approx((30, 12, 60, 24), abs=2.0)
    if letterbox:
        assert sx == pytest.approx(sy) and (img[: int(py)] == 128).all()  # aspect kept, grey padding


def test_per_class_nms() -> None:
    boxes = np.array([[0, 0, 10, 10], [1, 1, 11, 11], [0, 0, 10, 10], [50, 50, 60, 60]], dtype=float)
    scores = np.array([0.9, 0.8, 0.7, 0.6])
    keep = per_class_nms(boxes, scores, np.array([1, 1, 2, 1]), 0.5)
    assert keep.tolist() == [0, 2, 3]  # box 1 suppressed by its own class, box 2 (other class) kept


def test_real_detector_on_tum_desk(detector, tum_frame: Frame) -> None:  # type: ignore[no-untyped-def]
    dets = validate_detections(tum_frame, detector.detect(tum_frame))
    labels = [d.label for d in dets]
    chair_id = category("chair").id
    chairs = [d for d in dets if d.class_id == chair_id]
    assert len(chairs) >= 2, labels  # the two chairs in front of the desk
    assert "bottle" in labels, labels
    for d in dets:
        assert d.score >= detector.score_threshold
        x0, y0, x1, y1 = d.box
        assert 0 <= x0 < x1 <= 640 and 0 <= y0 < y1 <= 480
        ys, xs = np.nonzero(d.mask)
        assert xs.size > 0 and xs.min() >= np.floor(x0) and xs.max() < np.ceil(x1)
        assert ys.min() >= np.floor(y0) and ys.max() < np.ceil(y1)
        assert (tum_frame.depth[d.mask] > 0).all()  # depth masks hold valid depth only
    # The big chair at the bottom left: its box sits in the lower-left quarter of the image.
    big = max(chairs, key=lambda d: (d.box[2] - d.box[0]) * (d.box[3] - d.box[1]))
    assert big.box[0] < 100 and big.box[3] > 420 and big.box[2] < 330
    assert detector.detect(tum_frame)[0].box == dets[0].box  # deterministic


@pytest.mark.parametrize("name", sorted(BACKENDS))
def test_letterbox_finds_the_chairs_too(name: str, shared_dir: Path, tum_frame: Frame) -> None:
    det = create_detector(name, model_dir=str(shared_dir / "weights" / BACKENDS[name]), letterbox=True,
                          mask="box", classes=["chair"], threads=1)
    dets = det.detect(tum_frame)
    assert len(dets) >= 2 and {d.label for d in dets} == {"chair"}
    assert "resize=letterbox" in det.id and "mask=box" in det.id
    for d in dets:  # box masks are the boxes
        assert d.area == pytest.approx((d.box[2] - d.box[0]) * (d.box[3] - d.box[1]), rel=0.05)


def test_bad_frame_is_a_clear_error(detector, tum_frame: Frame) -> None:  # type: ignore[no-untyped-def]
    small = Frame(1, tum_frame.rgb[:240, :320], tum_frame.depth, tum_frame.K, np.eye(4))
    with pytest.raises(FrameError, match=r"uint8 RGB of the frame's size \(480, 640, 3\)"):
        detector.detect(small)
    floats = Frame(2, tum_frame.rgb.astype(np.float32), tum_frame.depth, tum_frame.K, np.eye(4))
    with pytest.raises(FrameError, match="float32"):
        detector.detect(floats)


def test_bad_options(shared_dir: Path) -> None:
    folder = str(shared_dir / "weights" / "yolo-fastest-1.1-xl")
    with pytest.raises(InputError, match="unknown yolo-fastest detector option"):
        create_detector("yolo-fastest", model_dir=folder, treshold=0.3)
    with pytest.raises(InputError, match="score_threshold"):
        create_detector("yolo-fastest", model_dir=folder, score_threshold=2)
    with pytest.raises(InputError, match=r"runs yolo-fastest-1\.1-xl, yolo-fastest-1\.1"):
        create_detector("yolo-fastest", model_dir=folder, model="centernet-mobilenetv3-coco")
    with pytest.raises(InputError, match="mask mode"):
        create_detector("centernet", model_dir=folder, mask="sam")


def test_smaller_yolo_from_the_same_folder(shared_dir: Path, tum_frame: Frame) -> None:
    det = create_detector("yolo-fastest", model="yolo-fastest-1.1", threads=1,
                          model_dir=str(shared_dir / "weights" / "yolo-fastest-1.1-xl"))
    assert det.id.startswith("yolo-fastest:yolo-fastest-1.1:")
    assert any(d.label == "chair" for d in det.detect(tum_frame))


def test_missing_model_names_the_install_command(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CAPNAV_MODELS", str(tmp_path / "none"))
    with pytest.raises(InputError, match="capnav models install centernet-mobilenetv3-coco"):
        create_detector("centernet")
    with pytest.raises(InputError, match="not an existing folder"):
        create_detector("centernet", model_dir=str(tmp_path / "nope"))


def test_corrupt_weights_are_refused_before_loading(shared_dir: Path, tmp_path: Path) -> None:
    src = shared_dir / "weights" / "centernet-mobilenetv3-coco"
    bad = tmp_path / "cn"
    shutil.copytree(src, bad)
    (bad / "centernet.onnx").chmod(0o644)
    data = (bad / "centernet.onnx").read_bytes()
    (bad / "centernet.onnx").write_bytes(data[: len(data) // 2])  # truncated
    with pytest.raises(ModelError, match=r"centernet.onnx has sha256 .* truncated, corrupt or different"):
        create_detector("centernet", model_dir=str(bad))


def test_candidates_below_the_threshold_come_weak(detector, tum_frame: Frame) -> None:  # type: ignore[no-untyped-def]
    """``detect`` is unchanged; ``detect_candidates`` adds the boxes from ``candidate_floor`` up to
    the threshold, marked weak, with the rival classes of their box as votes (the TUM desk is a
    table at 0.20 for CenterNet: docs/real-recording.md)."""
    strong = detector.detect(tum_frame)
    cand = validate_detections(tum_frame, detector.detect_candidates(tum_frame))
    assert [d.box for d in cand if not d.weak] == [d.box for d in strong]
    weak = [d for d in cand if d.weak]
    assert all(detector.candidate_floor <= d.score < detector.score_threshold for d in weak)
    assert all(not d.votes or max(d.votes, key=lambda k: d.votes[k]) == d.label for d in weak)
    if detector.backend == "centernet":
        assert "table" in {d.label for d in weak}
