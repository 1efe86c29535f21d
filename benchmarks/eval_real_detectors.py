"""Real COCO detectors vs the simulator detector on Sweet Home 3D apartments, per COCO category.

    .venv/bin/python benchmarks/eval_real_detectors.py --seeds 0 1 2 [--width 640 --height 480]
        [--cache data/bench] [--assets-dir DIR] [--weights ../shared/weights]
        [--detectors sim yolo-fastest centernet] [--stride 1]

Each apartment (``sh3d_data.dataset``: ``capnav sim --furniture sh3d --seed S``, rendered once and
cached) is mapped once per detector from the same frames (the ``sim`` detector at its default
noise, seed 0; the real ones with their defaults and masks from depth), and each map is scored
against the apartment's manifest by ``capnav.eval.map_quality.evaluate_map``. Per CapNav category
that a COCO class maps to (``capnav.perception.coco.TO_CAPNAV``), pooled over the apartments:

- recall: instances seen in >= 5 frames (>= 100 px each) with at least one map object on them;
- precision: map objects labelled with the category that lie on an instance (of any category);
- duplicates: map objects beyond the first on the category's instances, over the objects on them;
- category accuracy: objects on the category's instances that carry its label;
- size error: median over the category's mapped instances of ``map_quality.size_error`` (the larger
  of the caption width and height errors of the instance's best object).

Truth is read here only (evaluation); the detectors see pixels, depth and poses.
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
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

from bench_common import REPO, WEIGHT_FOLDERS, add_sh3d_args, table  # noqa: E402


def make_detector(name: str, weights: Path) -> Any:
    from capnav.perception import create_detector

    if name == "sim":
        return create_detector("sim", noise="default", seed=0)
    return create_detector(name, model_dir=str(weights / WEIGHT_FOLDERS[name]), threads=1)


def score(cmap: Any, manifest: Any, seen: dict[int, int], counts: dict[str, dict[str, float]],
          sizes: dict[str, list[float]], cats: set[str]) -> None:
    """Add one map's per-category counts (see the module docstring) to ``counts`` / ``sizes``."""
    from capnav.eval.map_quality import QualityConfig, evaluate_map

    q = evaluate_map(cmap, manifest, seen)
    min_frames = QualityConfig().min_frames
    on_instance: dict[int, str] = {}  # map object id -> category of the instance it lies on
    for rec in q.per_instance:
        c = rec["category"]
        for oid in rec["objects"]:
            on_instance[oid] = c
        if c not in cats:
            continue
        if (rec["frames_seen"] or 0) >= min_frames:
            counts[c]["seen"] += 1
            counts[c]["found"] += bool(rec["objects"])
        counts[c]["on"] += len(rec["objects"])
        counts[c]["dups"] += max(0, len(rec["objects"]) - 1)
        if "size_error" in rec:
            sizes[c].append(float(rec["size_error"]))
    labels = {o.id: o.label for o in cmap.objects}
    for oid, c in on_instance.items():
        if c in cats:
            counts[c]["right"] += labels[oid] == c
    for o in cmap.objects:
        if o.label in cats:
            counts[o.label]["labelled"] += 1
            counts[o.label]["labelled_on"] += o.id in on_instance


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_sh3d_args(ap)
    ap.add_argument("--weights", type=Path, default=Path(os.environ.get("CAPNAV_SHARED", REPO.parent / "shared"))
                    / "weights")
    ap.add_argument("--detectors", nargs="+", default=["sim", *WEIGHT_FOLDERS], choices=["sim", *WEIGHT_FOLDERS])
    ap.add_argument("--stride", type=int, default=1, help="map every k-th frame")
    args = ap.parse_args()
    dataset = importlib.import_module("sh3d_data").dataset  # beside this script

    from capnav.eval.map_quality import visible_frames
    from capnav.io.dataset import DatasetReader
    from capnav.mapping import build_map
    from capnav.perception.coco import TO_CAPNAV
    from capnav.sim.manifest import SceneManifest
    cats = sorted(set(TO_CAPNAV.values()))
    counts: dict[str, dict[str, dict[str, float]]] = {d: defaultdict(lambda: defaultdict(float))
                                                      for d in args.detectors}
    sizes: dict[str, dict[str, list[float]]] = {d: defaultdict(list) for d in args.detectors}
    totals: dict[str, dict[str, float]] = {d: defaultdict(float) for d in args.detectors}
    for seed in args.seeds:
        data = dataset(seed, args.cache, args.width, args.height, "sh3d", args.assets_dir)
        reader = DatasetReader(data)
        frames = [reader.frame(i) for i in range(0, len(reader), args.stride)]
        manifest = SceneManifest.load(data / "manifest.json")
        seen = visible_frames(frames)
        for name in args.detectors:
            t0 = time.thread_time()
            cmap = build_map(frames, detector=make_detector(name, args.weights), progress=False)
            totals[name]["seconds"] += time.thread_time() - t0
            totals[name]["frames"] += len(frames)
            totals[name]["objects"] += len(cmap.objects)
            totals[name]["merged"] += int(cmap.meta.get("merged_duplicates", 0))
            score(cmap, manifest, seen, counts[name], sizes[name], set(cats))
            print(f"seed {seed} {name}: {len(cmap.objects)} objects, {len(frames)} frames", flush=True)

    def pct(a: float, b: float) -> str:
        return f"{a / b:.0%} ({int(a)}/{int(b)})" if b else "-"

    rows = []
    for c in cats:
        seen_n = counts[args.detectors[0]][c]["seen"]
        if not seen_n and not any(counts[d][c]["labelled"] for d in args.detectors):
            continue
        for d in args.detectors:
            k = counts[d][c]
            s = sizes[d][c]
            rows.append([c if d == args.detectors[0] else "", d, pct(k["found"], k["seen"]),
                         pct(k["labelled_on"], k["labelled"]), pct(k["dups"], k["on"]), pct(k["right"], k["on"]),
                         f"{100 * np.median(s):.0f} cm" if s else "-"])
    table(f"per COCO-covered category, Sweet Home 3D apartments (seeds {' '.join(map(str, args.seeds))}, "
           f"{args.width}x{args.height}, every {args.stride}th frame)",
           ["category", "detector", "recall (seen)", "precision", "duplicates", "category acc.", "size error"], rows)
    rows = []
    for d in args.detectors:
        t = totals[d]
        allk = {key: sum(counts[d][c][key] for c in cats) for key in ("found", "seen", "labelled_on", "labelled",
                                                                       "dups", "on", "right")}
        rows.append([d, str(int(t["objects"])), pct(allk["found"], allk["seen"]),
                     pct(allk["labelled_on"], allk["labelled"]), pct(allk["dups"], allk["on"]),
                     pct(allk["right"], allk["on"]), str(int(t["merged"])),
                     f"{t['frames'] / max(t['seconds'], 1e-9):.1f}"])
    table("all COCO-covered categories pooled", ["detector", "objects", "recall", "precision", "duplicates",
                                                 "category acc.", "merged at export", "frames/s (CPU)"], rows)


if __name__ == "__main__":
    main()
