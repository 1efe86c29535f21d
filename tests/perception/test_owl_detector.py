"""The OWL-ViT / OWLv2 detector backend on tiny randomly initialised models built here.

Random weights detect garbage, so these tests check the plumbing and the properties a mapper
relies on (valid output, masks inside boxes, scores above the threshold, NMS, determinism, clear
refusals), plus the box -> mask logic and NMS on hand-made inputs where the right answer is known.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from _synth_scene import orbit
from scipy import ndimage
from typer.testing import CliRunner

from capnav.core.categories import NAMES, category
from capnav.core.errors import InputError
from capnav.perception import DETECTORS, create_detector, validate_detections
from capnav.perception import owl_detector as owl_mod
from capnav.perception.box_masks import (
    box_pixels,
    depth_box_mask,
    depth_modes,
    filled_box_mask,
    floor_pixels,
    grow_smooth,
    nearest_depth_mode,
)
from capnav.perception.nms import nms
from capnav.perception.owl_detector import batched_nms, parse_vocabulary, vocabulary_labels

torch = pytest.importorskip("torch")
transformers = pytest.importorskip("transformers")

MAX_TEXT = 16


def _byte_chars() -> list[str]:
    """The 256 printable stand-ins byte-level BPE uses for bytes (GPT-2 / CLIP convention)."""
    printable = [*range(ord("!"), ord("~") + 1), *range(ord("¡"), ord("¬") + 1), *range(ord("®"), ord("ÿ") + 1)]
    extra = [b for b in range(256) if b not in printable]
    return [chr(c) for c in printable] + [chr(256 + i) for i in range(len(extra))]


def _tiny_clip_tokenizer() -> Any:
    """A CLIP BPE tokenizer over single bytes (+ end-of-word forms) and one merge: enough to encode any text."""
    vocab: dict[str, int] = {}
    for c in _byte_chars():
        vocab[c] = len(vocab)
    for c in _byte_chars():
        vocab[c + "</w>"] = len(vocab)
    vocab["of</w>"] = len(vocab)
    vocab["<|startoftext|>"] = len(vocab)
    vocab["<|endoftext|>"] = len(vocab)
    return transformers.CLIPTokenizer(vocab=vocab, merges=[("o", "f</w>")], model_max_length=MAX_TEXT)


def _build_owl(folder: Path, kind: str, tok: Any) -> None:
    from transformers.models.owlv2.image_processing_pil_owlv2 import Owlv2ImageProcessorPil
    from transformers.models.owlvit.image_processing_pil_owlvit import OwlViTImageProcessorPil

    n = len(tok.get_vocab())
    text = dict(vocab_size=n, hidden_size=32, intermediate_size=64, num_hidden_layers=2, num_attention_heads=2,
                max_position_embeddings=MAX_TEXT, bos_token_id=n - 2, eos_token_id=n - 1, pad_token_id=n - 1)
    vision = dict(hidden_size=32, intermediate_size=64, num_hidden_layers=2, num_attention_heads=2, image_size=64,
                  patch_size=16)
    size = {"height": 64, "width": 64}
    torch.manual_seed(0)
    if kind == "owlv2":
        model = transformers.Owlv2ForObjectDetection(transformers.Owlv2Config(
            text_config=text, vision_config=vision, projection_dim=32))
        proc = transformers.Owlv2Processor(image_processor=Owlv2ImageProcessorPil(size=size), tokenizer=tok)
    else:
        model = transformers.OwlViTForObjectDetection(transformers.OwlViTConfig(
            text_config=text, vision_config=vision, projection_dim=32))
        proc = transformers.OwlViTProcessor(image_processor=OwlViTImageProcessorPil(size=size, crop_size=size),
                                            tokenizer=tok)
    with torch.no_grad():  # random box deltas saturate to degenerate boxes: use the patch priors, widened so they
        model.box_head.dense2.weight.zero_()  # overlap (NMS then has duplicates to remove)
        model.box_head.dense2.bias.copy_(torch.tensor([0.0, 0.0, 1.5, 1.5]))
    model.save_pretrained(folder)
    proc.save_pretrained(folder)


def _build_sam(folder: Path) -> None:
    from transformers.models.sam.image_processing_pil_sam import SamImageProcessorPil

    torch.manual_seed(0)
    cfg = transformers.SamConfig(
        vision_config=dict(hidden_size=32, output_channels=16, num_hidden_layers=2, num_attention_heads=2,
                           image_size=64, patch_size=16, window_size=2, global_attn_indexes=[1], num_pos_feats=8,
                           mlp_dim=64),
        prompt_encoder_config=dict(hidden_size=16, image_size=64, patch_size=16, mask_input_channels=4),
        mask_decoder_config=dict(hidden_size=16, mlp_dim=32, num_hidden_layers=2, num_attention_heads=2,
                                 iou_head_hidden_dim=16))
    transformers.SamModel(cfg).save_pretrained(folder)
    transformers.SamProcessor(image_processor=SamImageProcessorPil(
        size={"longest_edge": 64}, pad_size={"height": 64, "width": 64}, mask_size={"longest_edge": 16},
        mask_pad_size={"height": 16, "width": 16})).save_pretrained(folder)


@pytest.fixture(scope="module")
def models(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("models")
    tok = _tiny_clip_tokenizer()
    out = {kind: root / kind for kind in ("owlvit", "owlv2", "sam")}
    _build_owl(out["owlvit"], "owlvit", tok)
    _build_owl(out["owlv2"], "owlv2", tok)
    _build_sam(out["sam"])
    return out


@pytest.fixture(scope="module")
def frames() -> list:
    return orbit(3, width=160, height=120)


def _iou(a: tuple[float, ...], b: tuple[float, ...]) -> float:
    iw = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    ih = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    inter = iw * ih
    union = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - inter
    return inter / union if union > 0 else 0.0


def _check_properties(det: Any, frame: Any, threshold: float, max_n: int) -> list:
    dets = validate_detections(frame, det.detect(frame))
    h, w = frame.shape
    assert len(dets) <= max_n
    for d in dets:
        assert threshold <= d.score <= 1.0
        x0, y0, x1, y1 = d.box
        assert 0 <= x0 < x1 <= w and 0 <= y0 < y1 <= h
        assert d.area > 0
        assert not (d.mask & ~filled_box_mask(d.box, (h, w))).any(), "mask leaves its box"
        if d.class_id:
            assert category(d.class_id).name == d.label
    for i, a in enumerate(dets):  # per-class NMS held
        for b in dets[i + 1:]:
            if a.label == b.label:
                assert _iou(a.box, b.box) <= det.nms_iou + 1e-9
    return dets


# --- NMS and box -> mask on hand-made inputs ---------------------------------------------------


def test_nms_removes_duplicates_but_not_other_classes(monkeypatch: pytest.MonkeyPatch) -> None:
    boxes = np.array([[10, 10, 50, 50], [12, 11, 51, 49], [60, 60, 90, 90], [10, 10, 50, 50]], dtype=float)
    scores = np.array([0.6, 0.9, 0.5, 0.4])
    assert nms(boxes, scores, 0.5).tolist() == [1, 2]  # box 0 and 3 duplicate the better box 1
    assert nms(boxes, scores, 1.0).tolist() == [1, 0, 2, 3]  # nothing overlaps more than IoU 1
    monkeypatch.setattr(owl_mod, "_torchvision_batched_nms", lambda: None)  # the numpy path
    classes = np.array([1, 1, 1, 2])  # the last box is another class: it survives next to box 1
    assert batched_nms(boxes, scores, classes, 0.5).tolist() == [1, 2, 3]
    assert batched_nms(np.zeros((0, 4)), np.zeros(0), np.zeros(0, dtype=int), 0.5).tolist() == []
    with pytest.raises(InputError, match="3 scores"):
        nms(boxes, scores[:3], 0.5)


def _near_object_scene() -> tuple[np.ndarray, np.ndarray]:
    """A far wall (3 m) with a near object (1.2-1.4 m, slanted) and a sliver of floor in front."""
    depth = np.full((60, 80), 3.0, dtype=np.float32)
    obj = np.zeros(depth.shape, dtype=bool)
    obj[20:45, 30:50] = True
    obj[20:25, 30:34] = False  # a notch: the mask must follow the object, not its bounding rectangle
    depth[obj] = np.broadcast_to(1.2 + 0.01 * (np.arange(80) - 30), depth.shape)[obj]
    depth[50:60, :] = np.linspace(0.9, 1.1, 10, dtype=np.float32)[:, None]  # floor, nearer than the object
    depth[30:33, 38:41] = 0.0  # invalid pixels never join a mask
    return depth, obj


def test_depth_mask_keeps_the_near_object_not_the_wall_behind() -> None:
    depth, obj = _near_object_scene()
    box = (22.0, 12.0, 58.0, 52.0)  # the object, a wide margin of wall (more pixels than it) and 2 floor rows
    crop_wall = int((depth[12:52, 22:58] == 3.0).sum())
    assert crop_wall > 0.9 * obj.sum()
    m = depth_box_mask(depth, box)
    assert m.dtype == np.bool_ and m.shape == depth.shape
    expected = obj & (depth > 0)
    assert (m == expected).all()
    stray = depth.copy()
    stray[14, 24] = stray[15, 56] = 0.5  # two stray near pixels are not "the nearest object"
    assert (depth_box_mask(stray, box) == expected).all()


def test_depth_mask_takes_the_largest_component_and_handles_empty_boxes() -> None:
    depth = np.full((40, 40), 2.5, dtype=np.float32)
    depth[5:25, 5:25] = 1.0  # the object
    depth[30:33, 30:33] = 1.05  # a small far-apart blob at the same depth
    m = depth_box_mask(depth, (0, 0, 40, 40))
    assert m.sum() == 400 and m[5:25, 5:25].all()
    assert not depth_box_mask(np.zeros((40, 40), np.float32), (0, 0, 40, 40)).any()  # no valid depth
    assert not depth_box_mask(depth, (10, 10, 10, 30)).any()  # zero-width box
    with pytest.raises(InputError, match="band"):
        depth_box_mask(depth, (0, 0, 10, 10), band=0.0)


def test_slanted_object_is_grown_and_a_small_occluder_ignored() -> None:
    depth = np.full((60, 80), 3.0, dtype=np.float32)
    depth[10:50, 10:70] = np.linspace(1.0, 2.2, 60, dtype=np.float32)[None, :]  # a sofa seen at a slant
    box = (8.0, 8.0, 72.0, 52.0)
    full = depth_box_mask(depth, box)
    assert full[10:50, 10:70].all() and full.sum() == 40 * 60  # all of it, none of the wall
    front = depth_box_mask(depth, box, extent=0.0, method="mode")
    assert 0 < front.sum() < 40 * 20  # the mode method without growing: only its front band
    assert grow_smooth(depth, np.ones(depth.shape, bool), front).sum() == 40 * 60  # the jump to the wall stops it
    far = np.full((60, 80), 3.0, dtype=np.float32)
    far[10:50, 10:70] = 2.0  # the detected object
    far[38:50, 10:30] = 1.0  # a small nearer occluder (a tenth of the box): too weak a mode to win
    modes = depth_modes(far[8:52, 8:72])
    assert len(modes) >= 1 and all(m > 1.5 for m in modes)
    assert (depth_box_mask(far, (8.0, 8.0, 72.0, 52.0)) == (far == 2.0)).all()
    far[25:50, 10:45] = 1.0  # a big occluder is the known failure: the nearest strong surface is taken
    assert depth_modes(far[8:52, 8:72])[0] < 1.5


def _open_chair_before_wall() -> tuple[np.ndarray, np.ndarray]:
    """An open-frame chair 1.4-1.75 m away (two legs, a seat, the frame of an empty back) 0.4 m in
    front of a wall, floor rows at the bottom: the wall fills most of the chair's box."""
    depth = np.full((80, 80), 2.1, dtype=np.float32)
    rows = np.arange(80, dtype=np.float32)[:, None]
    depth[68:, :] = np.broadcast_to(1.2 + 0.012 * (79 - rows[68:]), (12, 80))  # floor, nearer than the wall
    chair = np.zeros(depth.shape, dtype=bool)
    chair[10:12, 25:55] = True  # top rail of the back
    chair[10:45, 25:27] = chair[10:45, 53:55] = True  # back posts
    chair[42:45, 25:55] = True  # seat edge
    chair[42:70, 27:29] = chair[42:70, 51:53] = True  # legs down to the floor
    cols = np.broadcast_to(np.arange(80, dtype=np.float32)[None, :], depth.shape)
    depth[chair] = (1.4 + 0.012 * (cols - 25))[chair]  # the chair is seen from the side
    return depth, chair


def test_open_chair_mask_keeps_the_chair_not_the_wall_behind() -> None:
    depth, chair = _open_chair_before_wall()
    box = (23.0, 8.0, 57.0, 70.0)
    wall = depth == 2.1
    assert wall[8:70, 23:57].sum() > 2 * chair.sum()  # most of the box is wall
    floor = np.zeros(depth.shape, dtype=bool)
    floor[68:] = ~chair[68:]  # what floor_pixels finds when the pose is known
    m = depth_box_mask(depth, box, exclude=floor)
    assert not (m & wall).any()
    assert (m & chair).sum() >= 0.95 * chair.sum() and not (m & ~chair).any()
    nofloor = depth_box_mask(depth, box)  # without the pose: still none of the wall
    assert not (nofloor & wall).any() and (nofloor & chair).sum() >= 0.95 * chair.sum()
    old = depth_box_mask(depth, box, exclude=floor, method="mode")  # a band around the nearest mode: part of it
    assert (old & chair).sum() < 0.8 * chair.sum()
    with pytest.raises(InputError, match="method"):
        depth_box_mask(depth, box, method="sam")


def test_floor_pixels_follow_the_pose() -> None:
    from capnav.core.geometry import Intrinsics, look_at_pose

    K = Intrinsics(fx=50.0, fy=50.0, cx=39.5, cy=29.5, width=80, height=60)
    T = look_at_pose(np.array([0.0, 0.0, 1.0]), yaw=0.0)  # 1 m above the floor, looking level
    v = np.arange(60, dtype=np.float64)[:, None]
    with np.errstate(divide="ignore"):
        floor_depth = np.where(v > K.cy, K.fy / (v - K.cy), 4.0)  # rows below the horizon see the floor at z = 0
    depth = np.broadcast_to(np.minimum(floor_depth, 4.0), (60, 80)).astype(np.float32).copy()
    depth[35:45, 30:50] = 2.0  # an object standing in front (its points are above the floor)
    fl = floor_pixels(depth, K, T)
    seen_floor = np.broadcast_to((v > K.cy) & (floor_depth <= 4.0), (60, 80)).copy()
    seen_floor[35:45, 30:50] = False
    assert (fl == seen_floor).all()


def test_box_helpers() -> None:
    assert box_pixels((-5.0, 2.2, 30.1, 99.0), (40, 20)) == (0, 2, 20, 40)
    m = filled_box_mask((1.5, 2.0, 4.0, 3.0), (5, 6))
    assert m.sum() == 3 and m[2, 1:4].all()
    assert nearest_depth_mode(np.r_[np.full(50, 3.0), np.full(40, 1.5)]) == pytest.approx(1.5, abs=0.05)
    with pytest.raises(InputError, match="not finite"):
        box_pixels((0.0, float("nan"), 1.0, 1.0), (4, 4))


def test_depth_masks_match_the_truth_on_rendered_frames() -> None:
    """Box = the true instance's box: the depth mask should be (mostly) that instance."""
    ious = []
    for f in orbit(12, width=160, height=120):
        floor = floor_pixels(f.depth, f.K, f.T_wc)
        inst = np.asarray(f.gt_instance)
        for iid in np.unique(inst[inst > 0]):
            truth = inst == iid
            if truth.sum() < 200:
                continue
            rows, cols = np.flatnonzero(truth.any(1)), np.flatnonzero(truth.any(0))
            box = (float(cols[0]), float(rows[0]), float(cols[-1] + 1), float(rows[-1] + 1))
            m = depth_box_mask(f.depth, box, exclude=floor)
            ious.append((m & truth).sum() / (m | truth).sum())
    assert len(ious) >= 8
    assert float(np.median(ious)) > 0.85 and float(np.min(ious)) > 0.5, ious


def test_vocabulary() -> None:
    assert parse_vocabulary(None) == list(NAMES)
    assert parse_vocabulary("sofa, couch ,red mug,sofa") == ["sofa", "couch", "red mug"]
    assert vocabulary_labels(["couch", "red mug"]) == [(category("sofa").id, "sofa"), (0, "red mug")]
    with pytest.raises(InputError, match="empty"):
        parse_vocabulary(" , ")


# --- the detector on tiny random models ----------------------------------------------------------


@pytest.mark.parametrize("kind", ["owlvit", "owlv2"])
def test_owl_detector_properties(models: dict[str, Path], frames: list, kind: str) -> None:
    det = create_detector("owl", model_path=str(models[kind]), score_threshold=0.0, max_detections=8,
                          mask="box", nms_iou=0.3)
    assert det.id.startswith(f"owl:{kind}:{kind}:vocab=capnav{len(NAMES)}:") and "mask=box" in det.id
    total = 0
    for f in frames:
        dets = _check_properties(det, f, 0.0, 8)
        total += len(dets)
        again = det.detect(f)  # deterministic: same frame, same detections
        assert [(d.box, d.label, d.score) for d in dets] == [(d.box, d.label, d.score) for d in again]
        assert all((a.mask == b.mask).all() for a, b in zip(dets, again, strict=True))
    assert total > 0, "a zero threshold should let the random model's boxes through"


@pytest.mark.parametrize("kind", ["owlvit", "owlv2"])
def test_boxes_are_in_frame_pixels(models: dict[str, Path], frames: list, kind: str) -> None:
    """OWL-ViT stretches the frame to a square, OWLv2 pads it (bottom/right) first: the pixel boxes
    must undo that, checked against the raw normalised (cx, cy, w, h) predictions."""
    det = create_detector("owl", model_path=models[kind], score_threshold=0.0, nms_iou=1.0, max_detections=1000,
                          mask="box", min_mask_area=0.0)
    f = frames[0]
    h, w = f.shape
    inputs = det.processor(text=[det.prompts], images=f.rgb, truncation=True, return_tensors="pt")
    with torch.inference_mode():
        out = det.model(**inputs)
    cx, cy, bw, bh = out.pred_boxes[0].double().numpy().T
    sx, sy = (max(h, w), max(h, w)) if kind == "owlv2" else (w, h)
    raw = np.stack([(cx - bw / 2) * sx, (cy - bh / 2) * sy, (cx + bw / 2) * sx, (cy + bh / 2) * sy], axis=1)
    raw[:, [0, 2]] = raw[:, [0, 2]].clip(0, w)
    raw[:, [1, 3]] = raw[:, [1, 3]].clip(0, h)
    scored = torch.sigmoid(out.logits[0].max(dim=-1).values).numpy() > 0  # post-processing keeps score > threshold
    raw = raw[((raw[:, 2] - raw[:, 0]) >= 1) & ((raw[:, 3] - raw[:, 1]) >= 1) & scored]
    got = det.boxes(f)[0]
    assert len(got) == len(raw) > 0
    assert np.allclose(np.sort(got, axis=0), np.sort(raw, axis=0), atol=1e-3)


def test_threshold_nms_and_cap_hold(models: dict[str, Path], frames: list) -> None:
    loose = create_detector("owl", model_path=models["owlv2"], score_threshold=0.0, nms_iou=1.0,
                            max_detections=1000, mask="box", min_mask_area=0.0)
    boxes, scores, _ = loose.boxes(frames[0])
    assert len(boxes) > 2
    tight = create_detector("owl", model_path=models["owlv2"], score_threshold=0.0, nms_iou=0.1,
                            max_detections=1000, mask="box", min_mask_area=0.0)
    assert len(tight.boxes(frames[0])[0]) < len(boxes)  # NMS removed overlapping boxes of a class
    thr = float(np.median(scores))
    high = create_detector("owl", model_path=models["owlv2"], score_threshold=thr, nms_iou=1.0,
                           max_detections=1000, mask="box", min_mask_area=0.0)
    s2 = high.boxes(frames[0])[1]
    assert len(s2) < len(scores) and (s2 >= thr).all()
    capped = create_detector("owl", model_path=models["owlv2"], score_threshold=0.0, nms_iou=1.0,
                             max_detections=2, mask="box", min_mask_area=0.0)
    b3, s3, _ = capped.boxes(frames[0])
    assert len(b3) == 2 and np.allclose(s3, np.sort(scores)[::-1][:2])


def test_depth_and_sam_masks(models: dict[str, Path], frames: list) -> None:
    depth_det = create_detector("owl", model_path=models["owlvit"], score_threshold=0.0, max_detections=8)
    assert "mask=depth" in depth_det.id
    sam_det = create_detector("owl", model_path=models["owlvit"], score_threshold=0.0, max_detections=8,
                              mask="sam", sam_path=str(models["sam"]), min_mask_area=0.0)
    assert "sam=sam" in sam_det.id
    for f in frames[:2]:
        for d in _check_properties(depth_det, f, 0.0, 8):
            assert (f.depth[d.mask] > 0).all()
            assert ndimage.label(d.mask, structure=np.ones((3, 3)))[1] == 1  # one connected surface
            assert not (d.mask & floor_pixels(f.depth, f.K, f.T_wc)).any()
        _check_properties(sam_det, f, 0.0, 8)
    boxes = depth_det.boxes(frames[0])[0]
    masks = sam_det.masks(frames[0], boxes)
    assert len(masks) == len(boxes) and all(m.shape == frames[0].shape and m.dtype == np.bool_ for m in masks)


def test_vocabulary_option_sets_labels_and_ids(models: dict[str, Path], frames: list) -> None:
    det = create_detector("owl", model_path=models["owlvit"], vocabulary=["couch", "red mug"], score_threshold=0.0,
                          mask="box")
    assert det.prompts == ["a photo of a couch", "a photo of a red mug"]
    assert ":vocab=2:" in det.id
    dets = det.detect(frames[0])
    assert dets and {(d.class_id, d.label) for d in dets} <= {(category("sofa").id, "sofa"), (0, "red mug")}


def test_refusals(models: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert "owl" in DETECTORS
    with pytest.raises(InputError, match="not an existing folder"):
        create_detector("owl", model_path=str(tmp_path / "nope"))
    (tmp_path / "file").write_text("x")
    with pytest.raises(InputError, match="not an existing folder"):
        create_detector("owl", model_path=str(tmp_path / "file"))
    with pytest.raises(InputError, match=r"no config\.json"):
        create_detector("owl", model_path=str(tmp_path))
    with pytest.raises(InputError, match="model_type 'sam'"):
        create_detector("owl", model_path=str(models["sam"]))
    with pytest.raises(InputError, match="needs sam_path"):
        create_detector("owl", model_path=str(models["owlvit"]), mask="sam")
    with pytest.raises(InputError, match="unknown mask mode"):
        create_detector("owl", model_path=str(models["owlvit"]), mask="polygon")
    with pytest.raises(InputError, match=r"unknown owl detector option.*colour"):
        create_detector("owl", model_path=str(models["owlvit"]), colour="red")
    with pytest.raises(InputError, match="needs model_path"):
        create_detector("owl")
    for bad in ({"score_threshold": 1.5}, {"score_threshold": "high"}, {"max_detections": 2.5},
                {"depth_band": None}, {"prompt": 3}, {"prompt": "a {} in {room}"}, {"sam_path": str(models["sam"])}):
        with pytest.raises(InputError, match=next(iter(bad))):
            create_detector("owl", model_path=str(models["owlvit"]), **bad)
    monkeypatch.setitem(sys.modules, "transformers", None)  # the runtime install: no extras
    with pytest.raises(InputError, match=r"python3? -m pip install .*\[detect\]'"):
        create_detector("owl", model_path=str(models["owlvit"]))


def test_importing_capnav_does_not_import_torch() -> None:
    code = ("import sys, capnav.perception, capnav.cli; from capnav.perception import DETECTORS; "
            "assert 'owl' in DETECTORS; bad = {'torch', 'transformers'} & set(sys.modules); "
            "assert not bad, bad")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


# --- capnav map --detector owl -------------------------------------------------------------------


def test_parse_detector_options() -> None:
    import typer

    from capnav.cli.map import parse_detector_options

    got = parse_detector_options(["model_path=/models/owlv2", "score_threshold=0.05", "vocabulary=[\"sofa\"]",
                                  "mask=sam", "flag=true", "prompt=a {} in a room"])
    assert got == {"model_path": "/models/owlv2", "score_threshold": 0.05, "vocabulary": ["sofa"], "mask": "sam",
                   "flag": True, "prompt": "a {} in a room"}
    for bad in (["no_equals"], ["=value"], ["bad key=1"], ["a=1", "a=2"]):
        with pytest.raises(typer.BadParameter):
            parse_detector_options(bad)


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from capnav.cli import app

    out = tmp_path_factory.mktemp("rec") / "ds"
    r = CliRunner().invoke(app, ["sim", "--seed", "1", "-o", str(out), "--frames", "3", "--width", "80",
                                 "--height", "60", "--rooms", "3"])
    assert r.exit_code == 0, r.output
    return out


def test_capnav_map_with_the_owl_detector(models: dict[str, Path], recording: Path, tmp_path: Path) -> None:
    from capnav.cli import app
    from capnav.io.mapfile import load_map

    out = tmp_path / "m.capnav"
    args = ["map", str(recording), "-o", str(out), "--detector", "owl", "--no-progress",
            "--detector-option", f"model_path={models['owlv2']}", "--detector-option", "score_threshold=0",
            "--detector-option", "max_detections=4", "--detector-option", "mask=sam",
            "--detector-option", f"sam_path={models['sam']}"]
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0, (r.output, r.exception)
    meta = load_map(out).meta
    assert meta["detector"].startswith("owl:owlv2:owlv2:") and "sam=sam" in meta["detector"]
    assert meta["frames_used"] == 3
    assert "detector owl:owlv2:" in " ".join(r.output.split())  # rich may wrap the line


def test_capnav_map_option_errors(models: dict[str, Path], recording: Path, tmp_path: Path) -> None:
    from capnav.cli import app
    from capnav.core.errors import CapNavError

    base = ["map", str(recording), "-o", str(tmp_path / "m.capnav"), "--no-progress", "--detector", "owl"]
    r = CliRunner().invoke(app, [*base, "--detector-option", "model_path"])
    assert r.exit_code == 2 and "KEY=VALUE" in r.output
    r = CliRunner().invoke(app, [*base, "--detector-option", f"model_path={models['owlvit']}",
                                 "--detector-option", "colour=red"])
    assert isinstance(r.exception, CapNavError) and "colour" in str(r.exception)
    r = CliRunner().invoke(app, [*base, "--detector-option", f"model_path={tmp_path / 'none'}"])
    assert isinstance(r.exception, InputError) and "not an existing folder" in str(r.exception)
    r = subprocess.run([sys.executable, "-m", "capnav.cli", *base, "--detector-option", "mask=box"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "needs model_path" in r.stderr and "Traceback" not in r.stderr
    sim = ["map", str(recording), "-o", str(tmp_path / "s.capnav"), "--no-progress", "--noise", "oracle",
           "--detector-option", "fp_rate=0.0"]
    r = CliRunner().invoke(app, sim)  # the sim detector still takes --noise/--seed, options are overrides
    assert r.exit_code == 0, (r.output, r.exception)
    assert "detector sim:oracle+custom:seed=0" in " ".join(r.output.split())
