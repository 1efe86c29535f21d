"""Real closed-vocabulary detectors for real pixels on a CPU, without PyTorch: COCO-80 models.

Two back-ends share one pipeline (``CocoDetector``): the image is resized to the model's square
input (stretched, as both models were trained, or ``letterbox=true``: scaled to fit and padded),
the model returns boxes with a COCO class and score, the boxes go back to the frame's pixels
(clipped), low scores and dropped classes go (``capnav.perception.coco``: COCO names map onto
CapNav's categories, other indoor classes keep their name), boxes of one class suppress each
other (NMS), and each kept box gets a mask from depth inside it (``capnav.perception.box_masks``,
as the owl detector does; ``mask=box`` fills the box).

* ``yolo-fastest``: Yolo-Fastest v1.1 (-xl by default, ``model=yolo-fastest-1.1`` for the smaller
  one) through OpenCV's Darknet reader (``pip install 'capnav[coco]'``: OpenCV 4; OpenCV 5 has no
  Darknet reader). Its region layers give (cx, cy, w, h) in 0..1 of the input, objectness, and
  80 class scores already multiplied by the objectness.
* ``centernet``: MobileNetV3 CenterNet as ONNX through onnxruntime (a core dependency). Its graph
  decodes the heat map itself: 100 rows (x1, y1, x2, y2, score, class) in 512-px input pixels.

Weights are found through ``model_dir`` or the installed copy (``capnav models install``), and
every file is checked against its pinned sha256 first (``capnav.perception.model_store``).
"""

from __future__ import annotations

import inspect
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from capnav.core.errors import FrameError, InputError, ModelError, pip_hint
from capnav.core.frame import Frame
from capnav.perception.base import DETECTORS, Detection, Detector
from capnav.perception.box_masks import depth_box_masks, filled_box_mask, floor_pixels, up_facing_pixels
from capnav.perception.coco import COCO80, class_table
from capnav.perception.model_store import locate
from capnav.perception.nms import per_class_nms

COCO_MASK_MODES = ("depth", "box")


def fit_to_square(rgb: NDArray[np.uint8], side: int, letterbox: bool
                  ) -> tuple[NDArray[np.uint8], tuple[float, float, float, float]]:
    """The model input (side, side, 3) and the map back: ``x = (x_in - px) / sx``, ``y = (y_in - py) / sy``
    as ``(sx, sy, px, py)``. Stretching scales each axis alone; a letterbox keeps the aspect and pads
    with grey (128)."""
    h, w = rgb.shape[:2]
    im = Image.fromarray(rgb)
    if not letterbox:
        return np.asarray(im.resize((side, side), Image.Resampling.BILINEAR)), (side / w, side / h, 0.0, 0.0)
    s = min(side / w, side / h)
    nw, nh = max(1, round(w * s)), max(1, round(h * s))
    px, py = (side - nw) // 2, (side - nh) // 2
    out = np.full((side, side, 3), 128, dtype=np.uint8)
    out[py:py + nh, px:px + nw] = np.asarray(im.resize((nw, nh), Image.Resampling.BILINEAR))
    return out, (nw / w, nh / h, float(px), float(py))


def _number(name: str, value: Any, lo: float, hi: float, lo_open: bool = False) -> float:
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and np.isfinite(value)
    if ok:
        v = float(value)
        ok = (lo < v if lo_open else lo <= v) and v <= hi
    if not ok:
        rng = f"{'(' if lo_open else '['}{lo:g}, {hi:g}]"
        raise InputError(f"{name} must be a number in {rng}, got {value!r}")
    return float(value)


class CocoDetector(Detector):
    """Shared pipeline of the COCO-80 back-ends; a subclass loads the model and runs ``raw``."""

    backend = "coco"
    models: tuple[str, ...] = ()

    def __init__(self, model: str | None = None, model_dir: str | Path | None = None, score_threshold: float = 0.3,
                 nms_iou: float = 0.45, max_detections: int = 50, classes: str | list[str] = "indoor",
                 letterbox: bool = False, threads: int = 0, mask: str = "depth", depth_band: float = 0.4,
                 depth_extent: float = 1.5, floor_height: float | None = 0.05, min_mask_area: float = 2e-4,
                 candidate_floor: float | None = 0.15, rival_floor: float = 0.1) -> None:
        model = self.models[0] if model is None else model
        if model not in self.models:
            raise InputError(f"the {self.backend} detector runs {', '.join(self.models)}; got model={model!r}")
        self.score_threshold = _number("score_threshold", score_threshold, 0.0, 1.0)
        self.nms_iou = _number("nms_iou", nms_iou, 0.0, 1.0, lo_open=True)
        floor = None if candidate_floor is None else _number("candidate_floor", candidate_floor, 0.0, 1.0)
        self.candidate_floor = floor if floor is not None and floor < self.score_threshold else None
        self.rival_floor = min(_number("rival_floor", rival_floor, 0.0, 1.0), self.candidate_floor or 1.0)
        self.depth_band = _number("depth_band", depth_band, 0.0, 10.0, lo_open=True)
        self.depth_extent = _number("depth_extent", depth_extent, 0.0, 10.0)
        self.floor_height = None if floor_height is None else _number("floor_height", floor_height, -100.0, 100.0)
        self.min_mask_area = _number("min_mask_area", min_mask_area, 0.0, 0.999)
        for key, val in (("max_detections", max_detections), ("threads", threads)):
            if isinstance(val, bool) or not isinstance(val, int) or val < (1 if key == "max_detections" else 0):
                raise InputError(f"{key} must be an integer >= {1 if key == 'max_detections' else 0}, got {val!r}")
        if not isinstance(letterbox, bool):
            raise InputError(f"letterbox must be true or false, got {letterbox!r}")
        if mask not in COCO_MASK_MODES:
            raise InputError(f"unknown mask mode {mask!r}; available: {', '.join(COCO_MASK_MODES)}")
        self.max_detections, self.threads, self.letterbox, self.mask_mode = max_detections, threads, letterbox, mask
        self.table = class_table(classes)
        self.labels = frozenset(t[1] for t in self.table if t is not None)
        self.classes_id = classes if isinstance(classes, str) and classes in ("indoor", "all") else \
            f"{sum(t is not None for t in self.table)}"
        if model_dir is not None and not isinstance(model_dir, (str, Path)):
            raise InputError(f"model_dir must be a folder path, got {model_dir!r}")
        self.model = model
        self.folder = locate(model, model_dir)
        self.side = self._load(self.folder)
        parts = [f"{self.backend}:{model}", f"thr={self.score_threshold:g}", f"nms={self.nms_iou:g}",
                 f"max={self.max_detections}", f"classes={self.classes_id}",
                 f"resize={'letterbox' if letterbox else 'stretch'}", f"mask={mask}"]
        if mask == "depth":
            parts.append(f"band={self.depth_band:g}:extent={self.depth_extent:g}")
            parts.append("floor=off" if self.floor_height is None else f"floor={self.floor_height:g}")
        if self.candidate_floor is not None:
            parts.append(f"candidates={self.candidate_floor:g}:rivals={self.rival_floor:g}")
        self.id = ":".join(parts)

    def _load(self, folder: Path) -> int:
        """Load the model from ``folder``; return the side of its square input."""
        raise NotImplementedError

    def raw(self, image: NDArray[np.uint8]) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
        """Model output on a (side, side, 3) RGB uint8 image: xyxy boxes in input pixels, scores, COCO indices."""
        raise NotImplementedError

    def boxes(self, frame: Frame, threshold: float | None = None
              ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
        """Boxes (N, 4) xyxy in the frame's pixels, scores (N,), COCO indices (N,): kept classes
        above the threshold (``score_threshold`` unless given), after per-class NMS and the cap,
        best first."""
        h, w = frame.shape
        rgb = np.asarray(frame.rgb)
        if rgb.shape != (h, w, 3) or rgb.dtype != np.uint8:
            raise FrameError(frame.index, f"the {self.backend} detector needs uint8 RGB of the frame's size "
                                          f"({h}, {w}, 3), got {rgb.dtype} {rgb.shape}")
        image, (sx, sy, px, py) = fit_to_square(rgb, self.side, self.letterbox)
        boxes, scores, cls = self.raw(image)
        boxes = boxes.copy()
        boxes[:, [0, 2]] = np.clip((boxes[:, [0, 2]] - px) / sx, 0.0, float(w))
        boxes[:, [1, 3]] = np.clip((boxes[:, [1, 3]] - py) / sy, 0.0, float(h))
        thr = self.score_threshold if threshold is None else threshold
        ok = np.isfinite(scores) & (scores >= thr) & (cls >= 0) & (cls < len(COCO80))
        ok &= np.all(np.isfinite(boxes), axis=1)
        ok &= ((boxes[:, 2] - boxes[:, 0]) >= 1.0) & ((boxes[:, 3] - boxes[:, 1]) >= 1.0)
        idx = np.flatnonzero(ok)
        idx = idx[[self.table[int(c)] is not None for c in cls[idx]]] if idx.size else idx
        boxes, scores, cls = boxes[idx], np.clip(scores[idx], 0.0, 1.0), cls[idx]
        keep = per_class_nms(boxes, scores, cls, self.nms_iou)[: self.max_detections]
        return boxes[keep], scores[keep], cls[keep]

    def masks(self, frame: Frame, boxes: NDArray[np.float64]) -> list[NDArray[np.bool_]]:
        """One (H, W) bool mask per box, cut to the box."""
        h, w = frame.shape
        box_list = [(float(b[0]), float(b[1]), float(b[2]), float(b[3])) for b in boxes]
        if not box_list:
            return []
        if self.mask_mode == "box":
            return [filled_box_mask(b, (h, w)) for b in box_list]
        depth = np.asarray(frame.depth)
        floor = None if self.floor_height is None else floor_pixels(depth, frame.K, frame.T_wc, self.floor_height)
        up = None if floor is None else up_facing_pixels(depth, frame.K, frame.T_wc)  # pose trusted like the floor
        raw = depth_box_masks(depth, box_list, band=self.depth_band, exclude=floor, extent=self.depth_extent,
                              up=up, K=frame.K)
        return [m & filled_box_mask(b, (h, w)) for m, b in zip(raw, box_list, strict=True)]

    def detect(self, frame: Frame) -> list[Detection]:
        return self._detect(frame, None)

    def detect_candidates(self, frame: Frame) -> list[Detection]:
        """Also the boxes scored from ``candidate_floor`` up to ``score_threshold``, marked ``weak``
        (per-class NMS over both, so a weak box never survives beside a confident one it repeats).
        A weak candidate carries as ``votes`` the other classes the model reads on the same box
        from ``rival_floor`` up (``rival_readings``): how sure the model is of what it is."""
        return self._detect(frame, self.candidate_floor)

    def _detect(self, frame: Frame, floor: float | None) -> list[Detection]:
        boxes, scores, cls = self.boxes(frame, None if floor is None else self.rival_floor)
        votes: list[dict[str, float]] = [{} for _ in scores]
        if floor is not None:
            names = [e[1] if (e := self.table[int(c)]) is not None else "" for c in cls]
            keep, votes = rival_readings(boxes, scores, names, self.score_threshold, floor)
            boxes, scores, cls = boxes[keep], scores[keep], cls[keep]
        h, w = frame.shape
        min_px = max(1, int(np.ceil(self.min_mask_area * h * w)))
        dets: list[Detection] = []
        for b, s, c, m, v in zip(boxes, scores, cls, self.masks(frame, boxes), votes, strict=True):
            if int(m.sum()) < min_px:
                continue
            entry = self.table[int(c)]
            assert entry is not None  # dropped classes are filtered in boxes()
            dets.append(Detection((float(b[0]), float(b[1]), float(b[2]), float(b[3])), entry[0], entry[1],
                                  float(s), m, v, weak=bool(s < self.score_threshold)))
        return dets


def rival_readings(boxes: NDArray[np.float64], scores: NDArray[np.float64], labels: list[str], threshold: float,
                   floor: float, same_iou: float = 0.6) -> tuple[NDArray[np.int64], list[dict[str, float]]]:
    """Which boxes to keep and their label votes. Confident boxes (>= ``threshold``) are kept as they
    are (no votes). A weak box (< ``threshold``), best first, that reaches ``floor`` and is not yet
    taken becomes a candidate and takes every other weak box of box IoU >= ``same_iou``: a model
    such as CenterNet reads several classes on one box (a cabinet as table 0.17, chair 0.16, couch
    0.12, bed 0.12), and those readings are the candidate's votes; weak boxes below ``floor`` that
    no candidate takes are dropped."""
    order = np.argsort(-scores, kind="stable")
    keep: list[int] = []
    votes: list[dict[str, float]] = []
    taken = np.zeros(len(scores), dtype=bool)
    area = np.maximum(boxes[:, 2] - boxes[:, 0], 0) * np.maximum(boxes[:, 3] - boxes[:, 1], 0)
    weak = scores < threshold
    for i in order:
        if not weak[i]:
            keep.append(int(i))
            votes.append({})
            continue
        if taken[i] or scores[i] < floor:
            continue
        taken[i] = True
        iw = np.clip(np.minimum(boxes[:, 2], boxes[i, 2]) - np.maximum(boxes[:, 0], boxes[i, 0]), 0, None)
        ih = np.clip(np.minimum(boxes[:, 3], boxes[i, 3]) - np.maximum(boxes[:, 1], boxes[i, 1]), 0, None)
        iou = iw * ih / np.maximum(area + area[i] - iw * ih, 1e-9)
        v = {labels[i]: float(scores[i])}
        for j in np.flatnonzero(weak & ~taken & (iou >= same_iou)):
            taken[j] = True
            v[labels[j]] = v.get(labels[j], 0.0) + float(scores[j])
        keep.append(int(i))
        votes.append(v if len(v) > 1 else {})
    order_kept = np.argsort(-scores[keep], kind="stable") if keep else np.zeros(0, dtype=np.int64)
    return np.asarray(keep, dtype=np.int64)[order_kept], [votes[k] for k in order_kept]


def _import_cv2() -> Any:
    try:
        import cv2
    except ImportError:
        raise InputError("the yolo-fastest detector needs OpenCV 4 (its Darknet reader): "
                         f"{pip_hint('capnav[coco]')}") from None
    if not hasattr(cv2, "dnn") or not hasattr(cv2.dnn, "readNetFromDarknet"):
        raise InputError(f"OpenCV {cv2.__version__} has no Darknet reader (OpenCV 5 dropped it): "
                         f"{pip_hint('opencv-python-headless<5')}")
    return cv2


class YoloFastestDetector(CocoDetector):
    """Yolo-Fastest v1.1 (Darknet) through OpenCV's dnn module."""

    backend = "yolo-fastest"
    models = ("yolo-fastest-1.1-xl", "yolo-fastest-1.1")

    def _load(self, folder: Path) -> int:
        cv2 = _import_cv2()
        cfg = folder / f"{self.model}.cfg"
        try:
            net = cv2.dnn.readNetFromDarknet(str(cfg), str(folder / f"{self.model}.weights"))
            net.setPreferableBackend(cv2.dnn.DNN_BACKEND_OPENCV)
            net.setPreferableTarget(cv2.dnn.DNN_TARGET_CPU)
        except cv2.error as e:
            raise ModelError(f"OpenCV cannot load {cfg}: {str(e).strip().splitlines()[-1]}") from None
        if self.threads:
            cv2.setNumThreads(self.threads)
        self._cv2, self._net = cv2, net
        self._outs = list(net.getUnconnectedOutLayersNames())
        sizes = {}
        for line in cfg.read_text().splitlines():
            key, _, val = line.partition("=")
            if key.strip() in ("width", "height") and key.strip() not in sizes:
                sizes[key.strip()] = int(val)
        if sizes.get("width") != sizes.get("height") or not sizes.get("width"):
            raise ModelError(f"{cfg}: expected a square input, got width/height {sizes}")
        return int(sizes["width"])

    def raw(self, image: NDArray[np.uint8]) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
        blob = self._cv2.dnn.blobFromImage(image, 1.0 / 255.0, swapRB=False, crop=False)
        self._net.setInput(blob)
        rows = np.concatenate([o.reshape(-1, o.shape[-1]) for o in self._net.forward(self._outs)]).astype(np.float64)
        probs = rows[:, 5:]
        cls = probs.argmax(axis=1).astype(np.int64)
        scores = probs[np.arange(len(rows)), cls]
        cx, cy, bw, bh = (rows[:, k] * self.side for k in range(4))
        boxes = np.stack([cx - bw / 2, cy - bh / 2, cx + bw / 2, cy + bh / 2], axis=1)
        return boxes, scores, cls


class CenterNetDetector(CocoDetector):
    """MobileNetV3 CenterNet (ONNX) through onnxruntime; the graph decodes its own boxes."""

    backend = "centernet"
    models = ("centernet-mobilenetv3-coco",)
    _INPUT, _OUTPUT = "tower_0/images:0", "tower_0/detections"

    def _load(self, folder: Path) -> int:
        import onnxruntime as ort

        path = folder / "centernet.onnx"
        so = ort.SessionOptions()
        if self.threads:
            so.intra_op_num_threads, so.inter_op_num_threads = self.threads, 1
        try:
            sess = ort.InferenceSession(str(path), so, providers=["CPUExecutionProvider"])
        except Exception as e:  # onnxruntime raises its own Fail/InvalidGraph/... types
            raise ModelError(f"onnxruntime cannot load {path}: {type(e).__name__}: {e}") from None
        inputs = {i.name: i.shape for i in sess.get_inputs()}
        if self._INPUT not in inputs or self._OUTPUT not in {o.name for o in sess.get_outputs()}:
            raise ModelError(f"{path} is not the CenterNet graph (inputs {sorted(inputs)})")
        shape = inputs[self._INPUT]
        if len(shape) != 4 or shape[1] != shape[2] or not isinstance(shape[1], int) or shape[3] != 3:
            raise ModelError(f"{path}: expected a square NHWC RGB input, got {shape}")
        self._sess = sess
        return int(shape[1])

    def raw(self, image: NDArray[np.uint8]) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
        x = image.astype(np.float32)[None]  # RGB 0..255, NHWC
        out = np.asarray(self._sess.run([self._OUTPUT], {self._INPUT: x})[0], dtype=np.float64).reshape(-1, 6)
        return out[:, :4], out[:, 4], np.rint(out[:, 5]).astype(np.int64)


def _factory(cls: type[CocoDetector]) -> Any:
    def make(**kwargs: Any) -> CocoDetector:
        known = [p for p in inspect.signature(CocoDetector.__init__).parameters if p != "self"]
        unknown = sorted(set(kwargs) - set(known))
        if unknown:
            raise InputError(f"unknown {cls.backend} detector option(s) {', '.join(unknown)}; "
                             f"valid: {', '.join(known)}")
        return cls(**kwargs)

    return make


DETECTORS.register("yolo-fastest")(_factory(YoloFastestDetector))
DETECTORS.register("centernet")(_factory(CenterNetDetector))
