"""A real open-vocabulary detector: OWL-ViT / OWLv2 through HF transformers, from a local folder.

This is the backend for real recordings (no simulator truth). The text queries are CapNav's
category names (``capnav.core.categories``) as prompts, so ``class_id`` and ``label`` mean the
same as the simulator detector's; other vocabulary entries get ``class_id`` 0. Boxes come from
the image processor's ``post_process_object_detection`` in the frame's pixels (OWLv2's boxes
scaled by its padded square's side), are clipped to the image, suppressed per class (NMS) and
cut to ``max_detections``. The mapper needs a mask per detection: ``mask="depth"`` (default)
keeps the object's depth surface inside the box (``capnav.perception.box_masks``; the floor,
world z < ``floor_height``, is left out; set ``floor_height=None`` when the poses do not put the
floor at z = 0), ``mask="sam"`` prompts a local SAM folder with all boxes of the frame at once,
``mask="box"`` fills the box. A mask is always cut to its box, and a detection whose mask is
smaller than ``min_mask_area`` (fraction of the image) is dropped.

Nothing is downloaded: folders are loaded with ``local_files_only=True`` and a path that is not
an existing folder is refused. torch / transformers are imported when a detector is built, not
when ``capnav.perception`` is imported (the runtime install has neither).
"""

from __future__ import annotations

import functools
import hashlib
import inspect
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.categories import NAMES, category
from capnav.core.errors import FrameError, InputError, ModelError, pip_hint
from capnav.core.frame import Frame
from capnav.perception.base import DETECTORS, Detection, Detector
from capnav.perception.box_masks import depth_box_masks, filled_box_mask, floor_pixels, up_facing_pixels
from capnav.perception.nms import per_class_nms

MASK_MODES = ("depth", "sam", "box")
OWL_MODEL_TYPES = ("owlvit", "owlv2")
_EXTRA_HINT = pip_hint('capnav[detect]')


def batched_nms(boxes: NDArray[np.floating], scores: NDArray[np.floating], classes: NDArray[np.integer],
                iou_threshold: float) -> NDArray[np.int64]:
    """Per-class NMS: boxes of different classes never suppress each other. Kept indices, best first.

    Uses ``torchvision.ops.batched_nms`` when torchvision imports and works with the installed
    torch; otherwise ``capnav.perception.nms.per_class_nms`` (same result up to the order of exact
    score ties).
    """
    b = np.asarray(boxes, dtype=np.float64).reshape(-1, 4)
    s = np.asarray(scores, dtype=np.float64).ravel()
    c = np.asarray(classes, dtype=np.int64).ravel()
    if not (b.shape[0] == s.shape[0] == c.shape[0]):
        raise InputError(f"batched_nms got {b.shape[0]} boxes, {s.shape[0]} scores, {c.shape[0]} classes")
    if b.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    tv = _torchvision_batched_nms()
    if tv is not None:
        return tv(b, s, c, iou_threshold)
    return per_class_nms(b, s, c, iou_threshold)


@functools.cache
def _torchvision_batched_nms() -> Any:
    """``torchvision.ops.batched_nms`` wrapped for numpy, or None when torchvision is missing or broken."""
    try:
        import torch
        from torchvision.ops import batched_nms as tv_nms

        tv_nms(torch.zeros((1, 4)), torch.zeros(1), torch.zeros(1, dtype=torch.int64), 0.5)  # probe the C++ op
    except Exception:  # ImportError, or a torchvision built for another torch ("operator does not exist")
        return None

    def run(b: NDArray[np.float64], s: NDArray[np.float64], c: NDArray[np.int64], thr: float) -> NDArray[np.int64]:
        keep = tv_nms(torch.from_numpy(b), torch.from_numpy(s), torch.from_numpy(c), float(thr))
        return np.asarray(keep.numpy(), dtype=np.int64)

    return run


def parse_vocabulary(vocabulary: str | Sequence[str] | None) -> list[str]:
    """The text queries: CapNav's category names by default, a list, or a comma-separated string."""
    if vocabulary is None:
        return list(NAMES)
    items = vocabulary.split(",") if isinstance(vocabulary, str) else list(vocabulary)
    words = [str(v).strip() for v in items]
    words = [w for w in dict.fromkeys(words) if w]
    if not words:
        raise InputError(f"detector vocabulary is empty: {vocabulary!r}")
    return words


def vocabulary_labels(words: Sequence[str]) -> list[tuple[int, str]]:
    """(class_id, label) per query word: a CapNav category (by name or synonym) gets its id and
    canonical name, any other word class 0 and itself."""
    out: list[tuple[int, str]] = []
    for w in words:
        try:
            c = category(w)
        except InputError:
            out.append((0, w))
        else:
            out.append((c.id, c.name))
    return out


def _require_folder(path: str | Path, what: str) -> Path:
    p = Path(path).expanduser()
    if not p.is_dir():
        raise InputError(f"{what} {str(path)!r} is not an existing folder (models are loaded from a local folder "
                         "only; nothing is downloaded)")
    if not (p / "config.json").is_file():
        raise InputError(f"{what} {str(p)!r} has no config.json: not a transformers model folder")
    return p


def _number(name: str, value: Any) -> float:
    """A finite float option (CLI values arrive as JSON or text), or an ``InputError`` naming it."""
    try:
        out = float(value)
    except (TypeError, ValueError):
        out = float("nan")
    if isinstance(value, bool) or not np.isfinite(out):
        raise InputError(f"{name} must be a finite number, got {value!r}")
    return out


def _import_backend() -> tuple[Any, Any]:
    try:
        import torch
        import transformers
    except ImportError as e:
        raise InputError(f"the owl detector needs torch and transformers ({e.name or e} is missing): "
                         f"{_EXTRA_HINT}") from None
    return torch, transformers


class OwlDetector(Detector):
    """Open-vocabulary instance detector: OWL-ViT / OWLv2 boxes + depth, SAM or box masks."""

    def __init__(self, model_path: str | Path, vocabulary: str | Sequence[str] | None = None,
                 score_threshold: float = 0.1, nms_iou: float = 0.5, mask: str = "depth",
                 sam_path: str | Path | None = None, device: str = "cpu", max_detections: int = 50,
                 prompt: str = "a photo of a {}", depth_band: float = 0.4, depth_extent: float = 1.5,
                 floor_height: float | None = 0.05, min_mask_area: float = 2e-4) -> None:
        score_threshold, nms_iou = _number("score_threshold", score_threshold), _number("nms_iou", nms_iou)
        depth_band, depth_extent = _number("depth_band", depth_band), _number("depth_extent", depth_extent)
        min_mask_area = _number("min_mask_area", min_mask_area)
        floor_height = None if floor_height is None else _number("floor_height", floor_height)
        if isinstance(max_detections, bool) or not isinstance(max_detections, int):
            raise InputError(f"max_detections must be an integer, got {max_detections!r}")
        if not isinstance(prompt, str) or not isinstance(mask, str) or not isinstance(device, str):
            raise InputError(f"prompt, mask and device must be text, got {prompt!r}, {mask!r}, {device!r}")
        if mask not in MASK_MODES:
            raise InputError(f"unknown mask mode {mask!r}; available: {', '.join(MASK_MODES)}")
        if not 0.0 <= float(score_threshold) <= 1.0:
            raise InputError(f"score_threshold must be in [0, 1], got {score_threshold}")
        if not 0.0 < float(nms_iou) <= 1.0:
            raise InputError(f"nms_iou must be in (0, 1], got {nms_iou}")
        if int(max_detections) < 1:
            raise InputError(f"max_detections must be >= 1, got {max_detections}")
        if "{}" not in prompt:
            raise InputError(f"prompt must contain '{{}}' where the category name goes, got {prompt!r}")
        if depth_band <= 0 or depth_extent < 0:
            raise InputError(f"depth_band must be > 0 and depth_extent >= 0 metres, got {depth_band}, {depth_extent}")
        if not 0.0 <= float(min_mask_area) < 1.0:
            raise InputError(f"min_mask_area is a fraction of the image in [0, 1), got {min_mask_area}")
        if mask == "sam" and sam_path is None:
            raise InputError("mask='sam' needs sam_path (a local SAM model folder)")
        if mask != "sam" and sam_path is not None:
            raise InputError(f"sam_path is only used with mask='sam' (mask is {mask!r})")
        folder = _require_folder(model_path, "owl model_path")
        sam_folder = _require_folder(sam_path, "sam_path") if sam_path is not None else None
        torch, transformers = _import_backend()
        self._torch = torch
        self.model_path, self.sam_path = folder, sam_folder
        self.words = parse_vocabulary(vocabulary)
        self.classes = vocabulary_labels(self.words)
        self.labels = frozenset(label for _, label in self.classes)
        try:
            self.prompts = [prompt.format(w) for w in self.words]
        except (IndexError, KeyError, ValueError) as e:
            raise InputError(f"prompt {prompt!r} must hold exactly one '{{}}' and no other braces ({e!r})") from None
        self.score_threshold, self.nms_iou = float(score_threshold), float(nms_iou)
        self.mask_mode, self.max_detections = mask, int(max_detections)
        self.depth_band, self.depth_extent = float(depth_band), float(depth_extent)
        self.floor_height = None if floor_height is None else float(floor_height)
        self.min_mask_area = float(min_mask_area)
        self.device = str(device)
        self.model_type = self._model_type(folder)
        model_cls = (transformers.Owlv2ForObjectDetection if self.model_type == "owlv2"
                     else transformers.OwlViTForObjectDetection)
        self.processor, self.model = self._load(transformers, folder, model_cls)
        self.sam_processor: Any = None
        self.sam_model: Any = None
        if sam_folder is not None:
            self.sam_processor, self.sam_model = self._load(transformers, sam_folder, transformers.SamModel)
        self.id = self._make_id(vocabulary is None)

    @staticmethod
    def _model_type(folder: Path) -> str:
        try:
            cfg = json.loads((folder / "config.json").read_text())
        except (OSError, ValueError) as e:
            raise InputError(f"cannot read {folder / 'config.json'}: {e}") from None
        mt = cfg.get("model_type") if isinstance(cfg, dict) else None
        if mt not in OWL_MODEL_TYPES:
            raise InputError(f"{folder} holds model_type {mt!r}; the owl detector needs one of "
                             f"{', '.join(OWL_MODEL_TYPES)}")
        return str(mt)

    def _load(self, transformers: Any, folder: Path, model_cls: Any) -> tuple[Any, Any]:
        try:
            processor = transformers.AutoProcessor.from_pretrained(str(folder), local_files_only=True)
            model = model_cls.from_pretrained(str(folder), local_files_only=True)
            model = model.to(self.device).eval()
        except Exception as e:  # corrupt weights, missing processor files, unknown device, ...
            raise ModelError(f"cannot load {model_cls.__name__} from {folder}: {type(e).__name__}: {e}") from None
        return processor, model

    def _make_id(self, default_vocab: bool) -> str:
        if default_vocab:
            vocab = f"capnav{len(self.words)}"
        else:
            vocab = f"{len(self.words)}:{hashlib.sha1('|'.join(self.prompts).encode()).hexdigest()[:8]}"
        parts = [f"owl:{self.model_type}:{self.model_path.name}", f"vocab={vocab}", f"thr={self.score_threshold:g}",
                 f"nms={self.nms_iou:g}", f"max={self.max_detections}", f"mask={self.mask_mode}"]
        if self.mask_mode == "depth":
            parts.append(f"band={self.depth_band:g}:extent={self.depth_extent:g}")
            parts.append("floor=off" if self.floor_height is None else f"floor={self.floor_height:g}")
        if self.sam_path is not None:
            parts.append(f"sam={self.sam_path.name}")
        return ":".join(parts)

    def boxes(self, frame: Frame) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
        """Boxes (N, 4) xyxy pixels, scores (N,), vocabulary indices (N,) after clipping, NMS and the cap."""
        torch = self._torch
        h, w = frame.shape
        rgb = np.asarray(frame.rgb)
        if rgb.shape != (h, w, 3) or rgb.dtype != np.uint8:
            raise FrameError(frame.index, f"the owl detector needs uint8 rgb ({h}, {w}, 3), "
                                          f"got {rgb.dtype} {rgb.shape}")
        # OWL's text encoder has 16 positions: a long prompt is cut rather than failing the frame.
        inputs = self.processor(text=[self.prompts], images=rgb, truncation=True, return_tensors="pt").to(self.device)
        # OWLv2 pads the image to a square (bottom / right) before resizing, so its boxes are relative
        # to that square: scaling by (side, side) is right both for transformers versions that scale
        # OWLv2 boxes per axis and for those that already use max(h, w).
        side = max(h, w)
        target = (side, side) if self.model_type == "owlv2" else (h, w)
        with torch.inference_mode():
            outputs = self.model(**inputs)
            res = self.processor.image_processor.post_process_object_detection(
                outputs, threshold=self.score_threshold, target_sizes=[target])[0]
        boxes = res["boxes"].detach().cpu().double().numpy().reshape(-1, 4)
        scores = res["scores"].detach().cpu().double().numpy().ravel()
        labels = res["labels"].detach().cpu().numpy().astype(np.int64).ravel()
        boxes[:, [0, 2]] = np.clip(boxes[:, [0, 2]], 0.0, float(w))
        boxes[:, [1, 3]] = np.clip(boxes[:, [1, 3]], 0.0, float(h))
        ok = ((boxes[:, 2] - boxes[:, 0]) >= 1.0) & ((boxes[:, 3] - boxes[:, 1]) >= 1.0) & np.isfinite(scores)
        ok &= scores >= self.score_threshold
        boxes, scores, labels = boxes[ok], np.clip(scores[ok], 0.0, 1.0), labels[ok]
        keep = batched_nms(boxes, scores, labels, self.nms_iou)[: self.max_detections]
        return boxes[keep], scores[keep], labels[keep]

    def masks(self, frame: Frame, boxes: NDArray[np.float64]) -> list[NDArray[np.bool_]]:
        """One (H, W) bool mask per box, each cut to its box."""
        h, w = frame.shape
        box_list = [(float(b[0]), float(b[1]), float(b[2]), float(b[3])) for b in boxes]
        if not box_list:
            return []
        if self.mask_mode == "sam":
            raw = self._sam_masks(frame, box_list)
        elif self.mask_mode == "depth":
            depth = np.asarray(frame.depth)
            floor = None if self.floor_height is None else floor_pixels(depth, frame.K, frame.T_wc, self.floor_height)
            up = None if floor is None else up_facing_pixels(depth, frame.K, frame.T_wc)  # pose trusted like the floor
            raw = depth_box_masks(depth, box_list, band=self.depth_band, exclude=floor, extent=self.depth_extent,
                                  up=up, K=frame.K)
        else:
            raw = [filled_box_mask(b, (h, w)) for b in box_list]
        return [m & filled_box_mask(b, (h, w)) for m, b in zip(raw, box_list, strict=True)]

    def _sam_masks(self, frame: Frame, boxes: list[tuple[float, float, float, float]]) -> list[NDArray[np.bool_]]:
        torch = self._torch
        h, w = frame.shape
        inputs = self.sam_processor(images=np.asarray(frame.rgb), input_boxes=[[list(b) for b in boxes]],
                                    return_tensors="pt").to(self.device)
        with torch.inference_mode():
            out = self.sam_model(**inputs, multimask_output=False)
        masks = self.sam_processor.post_process_masks(out.pred_masks.cpu(), inputs["original_sizes"].cpu(),
                                                      inputs["reshaped_input_sizes"].cpu())[0]
        arr = np.asarray(masks.numpy(), dtype=bool).reshape(len(boxes), -1, h, w)
        return [arr[k, 0] for k in range(len(boxes))]

    def detect(self, frame: Frame) -> list[Detection]:
        boxes, scores, labels = self.boxes(frame)
        h, w = frame.shape
        min_px = max(1, int(np.ceil(self.min_mask_area * h * w)))
        dets: list[Detection] = []
        for b, s, lab, m in zip(boxes, scores, labels, self.masks(frame, boxes), strict=True):
            if int(m.sum()) < min_px:
                continue
            class_id, label = self.classes[int(lab)]
            box = (float(b[0]), float(b[1]), float(b[2]), float(b[3]))
            dets.append(Detection(box, class_id, label, float(s), m))
        return dets


@DETECTORS.register("owl")
def _make_owl(**kwargs: Any) -> OwlDetector:
    known = [p for p in inspect.signature(OwlDetector.__init__).parameters if p != "self"]
    unknown = sorted(set(kwargs) - set(known))
    if unknown:
        raise InputError(f"unknown owl detector option(s) {', '.join(unknown)}; valid: {', '.join(known)}")
    if "model_path" not in kwargs:
        raise InputError("the owl detector needs model_path (a local OWL-ViT / OWLv2 folder), "
                         "e.g. --detector-option model_path=/models/owlv2")
    return OwlDetector(**kwargs)
