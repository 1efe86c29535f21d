"""Real COCO detectors vs the simulator detector on Sweet Home 3D apartments, per COCO category.

    .venv/bin/python benchmarks/eval_real_detectors.py --seeds 0 1 2 [--width 640 --height 480]
        [--cache data/bench] [--assets-dir DIR] [--weights ../shared/weights]
        [--detectors sim yolo-fastest centernet] [--stride 1] [--depth-noise] [--surface-items]
        [--json out.json]

Each apartment (``sh3d_data.dataset``: ``capnav sim --furniture sh3d --seed S``, rendered once and
cached) is mapped once per detector from the same frames (the ``sim`` detector at its default
noise, seed 0; the real ones with their defaults and masks from depth), and each map is scored
against the apartment's manifest by ``capnav.eval.map_quality.evaluate_map``. Per CapNav category
that a COCO class maps to (``capnav.perception.coco.TO_CAPNAV``), pooled over the apartments:

- recall: instances seen in >= 5 frames (>= 100 px each) with at least one map object on them;
- precision: map objects labelled with the category that lie on an instance (of any category);
  pooled, "on no instance" counts every map object (of any label) on no instance at all;
- duplicates: map objects beyond the first on the category's instances, over the objects on them;
- category accuracy: objects on the category's instances that carry its label;
- size error: median over the category's mapped instances of ``map_quality.size_error`` (the larger
  of the caption width and height errors of the instance's best object), in cm and relative to the
  truth (``surface_quality.relative_size_error``).

With ``--surface-items`` (``capnav sim --surface-items``: cups, bottles, books, vases, bowls and
laptops on tables, counters and shelves) a second table scores the small things per kind
(``capnav.eval.surface_quality``): recall, duplicates, size error, and how often the supporting
piece's map object absorbed the item (holds points inside it); and per support category how often
its label went to a thing on it. ``--json`` writes every figure for docs/perception.md.

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
          sizes: dict[str, list[float]], cats: set[str], rel: dict[str, list[float]] | None = None) -> None:
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
            if rel is not None:
                from capnav.eval.surface_quality import relative_size_error

                best = max((o for o in cmap.objects if o.id in rec["objects"]), key=lambda o: o.hits)
                rel[c].append(relative_size_error(best.extent_max - best.extent_min, manifest.object(rec["instance"])))
    labels = {o.id: o.label for o in cmap.objects}
    for oid, c in on_instance.items():
        if c in cats:
            counts[c]["right"] += labels[oid] == c
    for o in cmap.objects:
        if o.label in cats:
            counts[o.label]["labelled"] += 1
            counts[o.label]["labelled_on"] += o.id in on_instance
        counts[""]["off"] += o.id not in on_instance  # on no instance of any category: a false object


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_sh3d_args(ap)
    ap.add_argument("--weights", type=Path, default=Path(os.environ.get("CAPNAV_SHARED", REPO.parent / "shared"))
                    / "weights")
    ap.add_argument("--detectors", nargs="+", default=["sim", *WEIGHT_FOLDERS], choices=["sim", *WEIGHT_FOLDERS])
    ap.add_argument("--stride", type=int, default=1, help="map every k-th frame")
    ap.add_argument("--depth-noise", action="store_true", help="render with consumer RGB-D depth noise")
    ap.add_argument("--surface-items", action="store_true", help="small things on tables, counters and shelves")
    ap.add_argument("--json", type=Path, default=None, help="write every figure here")
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
    rel: dict[str, dict[str, list[float]]] = {d: defaultdict(list) for d in args.detectors}
    surf: dict[str, dict[str, dict[str, Any]]] = {d: {} for d in args.detectors}
    for seed in args.seeds:
        data = dataset(seed, args.cache, args.width, args.height, "sh3d", args.assets_dir, args.depth_noise,
                       args.surface_items)
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
            score(cmap, manifest, seen, counts[name], sizes[name], set(cats), rel[name])
            if manifest.items:
                from capnav.eval.surface_quality import surface_report

                for key, rec in surface_report(cmap, manifest, seen).items():
                    acc = surf[name].setdefault(key, {})
                    for f, v in rec.items():
                        acc[f] = acc.get(f, [] if isinstance(v, list) else 0) + v
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
            r = rel[d][c]
            rows.append([c if d == args.detectors[0] else "", d, pct(k["found"], k["seen"]),
                         pct(k["labelled_on"], k["labelled"]), pct(k["dups"], k["on"]), pct(k["right"], k["on"]),
                         f"{100 * np.median(s):.0f} cm" if s else "-", f"{100 * np.median(r):.0f}%" if r else "-"])
    scene = ("sh3d" + (", depth noise" if args.depth_noise else "") + (", surface items" if args.surface_items
                                                                         else ""))
    table(f"per COCO-covered category, Sweet Home 3D apartments ({scene}; seeds {' '.join(map(str, args.seeds))}, "
           f"{args.width}x{args.height}, every {args.stride}th frame)",
           ["category", "detector", "recall (seen)", "precision", "duplicates", "category acc.", "size error",
            "size error (rel.)"], rows)
    rows = []
    for d in args.detectors:
        t = totals[d]
        allk = {key: sum(counts[d][c][key] for c in cats) for key in ("found", "seen", "labelled_on", "labelled",
                                                                       "dups", "on", "right")}
        rows.append([d, str(int(t["objects"])), str(int(counts[d][""]["off"])), pct(allk["found"], allk["seen"]),
                     pct(allk["labelled_on"], allk["labelled"]), pct(allk["dups"], allk["on"]),
                     pct(allk["right"], allk["on"]), str(int(t["merged"])),
                     f"{t['frames'] / max(t['seconds'], 1e-9):.1f}"])
    table("all COCO-covered categories pooled", ["detector", "objects", "on no instance", "recall", "precision",
                                                 "duplicates",
                                                 "category acc.", "merged at export", "frames/s (CPU)"], rows)
    if any(surf.values()):
        rows = []
        for key in sorted({k for d in args.detectors for k in surf[d] if k.startswith("item:")}):
            for d in args.detectors:
                k = surf[d].get(key, {})
                e = k.get("size_errors", [])
                rows.append([key[5:] if d == args.detectors[0] else "", d, pct(k.get("found", 0), k.get("seen", 0)),
                             pct(k.get("dups", 0), k.get("on", 0)), f"{100 * np.median(e):.0f}%" if e else "-",
                             pct(k.get("absorbed", 0), k.get("seen", 0))])
        table("small things on surfaces, per kind (seen >= 5 frames)",
              ["item", "detector", "recall", "duplicates", "size error (rel.)", "absorbed by support"], rows)
        rows = []
        for key in sorted({k for d in args.detectors for k in surf[d] if k.startswith("support:")}):
            for d in args.detectors:
                k = surf[d].get(key, {})
                rows.append([key[8:] if d == args.detectors[0] else "", d, str(k.get("supports", 0)),
                             pct(k.get("mapped", 0), k.get("supports", 0)), pct(k.get("outvoted", 0),
                                                                                k.get("mapped", 0))])
        table("supports of the small things", ["support", "detector", "with items seen", "mapped",
                                               "label outvoted by an item"], rows)
    if args.json is not None:
        import json

        from capnav.core.atomic import write_text

        blob = {"seeds": args.seeds, "width": args.width, "height": args.height, "stride": args.stride,
                "depth_noise": args.depth_noise, "surface_items": args.surface_items,
                "categories": {d: {c: {**counts[d][c], "size_error_cm": float(100 * np.median(sizes[d][c]))
                                       if sizes[d][c] else None,
                                       "size_error_rel": float(np.median(rel[d][c])) if rel[d][c] else None}
                                   for c in cats} for d in args.detectors},
                "surfaces": {d: {k: {f: (float(np.median(v)) if v else None) if isinstance(v, list) else v
                                     for f, v in rec.items()} for k, rec in surf[d].items()}
                             for d in args.detectors}}
        write_text(args.json, json.dumps(blob, indent=1) + "\n")


if __name__ == "__main__":
    main()
