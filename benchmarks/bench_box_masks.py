"""Masks from boxes (``capnav.perception.box_masks``): the object's own surfaces vs the old mode.

    .venv/bin/python benchmarks/bench_box_masks.py --seeds 0 1 2 [--width 640 --height 480]
        [--cache data/bench] [--assets-dir DIR] [--view-stride 3] [--map-stride 1] [--pad 0.05]

A detector that gives boxes only (the COCO detectors, OWL-ViT) leaves the mask to
``depth_box_mask``. This measures it on Sweet Home 3D apartments (``sh3d_data.dataset``, rendered
once and cached) with the *true* boxes, so only the mask is tested: each instance's tight box in
the truth image, grown by ``--pad`` of its size on each side (a detector's box is rarely tight).
Truth is read here only (evaluation).

1. Per view (every ``--view-stride``-th frame, instances showing >= 0.2% of the image): IoU of
   the mask with the true instance mask, and the share of mask pixels that are not the instance
   (what the mask took in from the wall, floor or neighbours), for ``method="mode"`` (the
   nearest strong depth mode grown along smooth depth, the first method) and ``"surfaces"``.
2. Per map: the whole pass mapped with those masks (labels from the truth, every
   ``--map-stride``-th frame), objects matched to instances by ``capnav.eval.map_quality``, and
   the size error of each matched instance's object (``map_quality.size_error``: the larger of the
   caption width and height errors), median per category.
"""

from __future__ import annotations

import os

for _v in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import importlib  # noqa: E402
import time  # noqa: E402
from collections import defaultdict  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from numpy.typing import NDArray  # noqa: E402

from bench_common import add_sh3d_args, table  # noqa: E402
from capnav.core.categories import BY_ID  # noqa: E402
from capnav.core.frame import Frame  # noqa: E402
from capnav.perception.base import Detection, Detector  # noqa: E402
from capnav.perception.box_masks import MASK_METHODS, depth_box_mask, floor_pixels  # noqa: E402

CATEGORIES = ("chair", "table", "lamp")
MIN_AREA = 0.002


def truth_boxes(frame: Frame, pad: float) -> list[tuple[int, str, tuple[float, float, float, float],
                                                          NDArray[np.bool_]]]:
    """(instance id, category, padded box, true mask) of the instances showing >= MIN_AREA."""
    assert frame.gt_instance is not None and frame.gt_category is not None
    inst = np.asarray(frame.gt_instance)
    cat = np.asarray(frame.gt_category)
    h, w = inst.shape
    out = []
    ids, counts = np.unique(inst[cat > 0], return_counts=True)
    for iid, n in zip(ids, counts, strict=True):
        if n < MIN_AREA * h * w:
            continue
        truth = inst == iid
        rows, cols = np.flatnonzero(truth.any(1)), np.flatnonzero(truth.any(0))
        py, px = pad * (rows[-1] + 1 - rows[0]), pad * (cols[-1] + 1 - cols[0])
        box = (max(0.0, cols[0] - px), max(0.0, rows[0] - py), min(float(w), cols[-1] + 1 + px),
               min(float(h), rows[-1] + 1 + py))
        cid = int(np.bincount(cat[truth]).argmax())
        if cid in BY_ID:
            out.append((int(iid), BY_ID[cid].name, box, truth))
    return out


class TruthBoxDetector(Detector):
    """Benchmark only: true boxes and labels, masks from depth by ``method``."""

    def __init__(self, method: str, pad: float) -> None:
        self.method, self.pad = method, pad
        self.id = f"truth-boxes:{method}"

    def detect(self, frame: Frame) -> list[Detection]:
        floor = floor_pixels(frame.depth, frame.K, frame.T_wc)
        dets = []
        for _, name, box, _ in truth_boxes(frame, self.pad):
            m = depth_box_mask(frame.depth, box, exclude=floor, method=self.method)
            if m.sum() >= 10:
                from capnav.core.categories import category

                dets.append(Detection(box, category(name).id, name, 0.9, m))
        return dets


def per_view(frames: list[Frame], pad: float) -> tuple[dict[str, dict[str, list[float]]], dict[str, float]]:
    stats: dict[str, dict[str, list[float]]] = defaultdict(lambda: defaultdict(list))
    secs = dict.fromkeys(MASK_METHODS, 0.0)
    for f in frames:
        floor = floor_pixels(f.depth, f.K, f.T_wc)
        for _, name, box, truth in truth_boxes(f, pad):
            key = name if name in CATEGORIES else "other"
            for method in MASK_METHODS:
                t0 = time.thread_time()
                m = depth_box_mask(f.depth, box, exclude=floor, method=method)
                secs[method] += time.thread_time() - t0
                union = int((m | truth).sum())
                iou = float((m & truth).sum()) / union if union else 0.0
                spill = float((m & ~truth).sum()) / max(int(m.sum()), 1)
                for k in (key, "all"):
                    stats[k][f"iou:{method}"].append(iou)
                    stats[k][f"spill:{method}"].append(spill)
    return stats, secs


def map_sizes(data: Path, method: str, pad: float, stride: int) -> dict[str, list[float]]:
    from capnav.eval.map_quality import evaluate_map
    from capnav.io.dataset import DatasetReader
    from capnav.mapping import build_map
    from capnav.sim.manifest import SceneManifest

    reader = DatasetReader(data)
    manifest = SceneManifest.load(data / "manifest.json")
    frames = (reader.frame(i) for i in range(0, len(reader), stride))
    cmap = build_map(frames, detector=TruthBoxDetector(method, pad), progress=False)
    q = evaluate_map(cmap, manifest)
    out: dict[str, list[float]] = defaultdict(list)
    for rec in q.per_instance:
        if "size_error" in rec:
            key = rec["category"] if rec["category"] in CATEGORIES else "other"
            out[key].append(rec["size_error"])
            out["all"].append(rec["size_error"])
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_sh3d_args(ap)
    ap.add_argument("--view-stride", type=int, default=3)
    ap.add_argument("--map-stride", type=int, default=1)
    ap.add_argument("--pad", type=float, default=0.05)
    ap.add_argument("--no-map", action="store_true", help="per-view figures only")
    args = ap.parse_args()
    dataset = importlib.import_module("sh3d_data").dataset  # beside this script

    from capnav.io.dataset import DatasetReader
    view: dict[str, dict[str, list[float]]] = defaultdict(lambda: defaultdict(list))
    sizes: dict[str, dict[str, list[float]]] = {m: defaultdict(list) for m in MASK_METHODS}
    secs = dict.fromkeys(MASK_METHODS, 0.0)
    for seed in args.seeds:
        data = dataset(seed, args.cache, args.width, args.height, "sh3d", args.assets_dir)
        reader = DatasetReader(data)
        frames = [reader.frame(i) for i in range(0, len(reader), args.view_stride)]
        st, sc = per_view(frames, args.pad)
        for k, d in st.items():
            for kk, v in d.items():
                view[k][kk] += v
        for m in MASK_METHODS:
            secs[m] += sc[m]
        if not args.no_map:
            for m in MASK_METHODS:
                for k, v in map_sizes(data, m, args.pad, args.map_stride).items():
                    sizes[m][k] += v

    keys = [*CATEGORIES, "other", "all"]
    rows = []
    for k in keys:
        d = view.get(k)
        if not d:
            continue
        rows.append([k, str(len(d["iou:mode"])),
                     f"{np.median(d['iou:mode']):.2f} / {np.median(d['iou:surfaces']):.2f}",
                     f"{np.mean(d['iou:mode']):.2f} / {np.mean(d['iou:surfaces']):.2f}",
                     f"{np.mean(d['spill:mode']):.1%} / {np.mean(d['spill:surfaces']):.1%}"])
    n_masks = len(view["all"]["iou:mode"])
    table(f"mask vs true instance, true boxes +{args.pad:.0%} (seeds {' '.join(map(str, args.seeds))}, "
           f"{args.width}x{args.height}, every {args.view_stride}th frame); mode / surfaces",
           ["category", "views", "median IoU", "mean IoU", "mask pixels off the instance"], rows)
    print(f"CPU per mask: mode {1000 * secs['mode'] / max(n_masks, 1):.1f} ms, "
          f"surfaces {1000 * secs['surfaces'] / max(n_masks, 1):.1f} ms")
    if not args.no_map:
        rows = []
        for k in keys:
            a, b = sizes["mode"].get(k, []), sizes["surfaces"].get(k, [])
            if not a and not b:
                continue
            both = bool(a and b)
            rows.append([k, f"{len(a)} / {len(b)}",
                         f"{100 * np.median(a):.0f} / {100 * np.median(b):.0f} cm" if both else "-",
                         f"{np.mean(np.asarray(a) > 0.2):.0%} / {np.mean(np.asarray(b) > 0.2):.0%}" if both else "-"])
        table(f"map object size error (caption width/height, worst of the two), every {args.map_stride}th frame; "
               "mode / surfaces", ["category", "instances mapped", "median size error", "error > 20 cm"], rows)


if __name__ == "__main__":
    main()
