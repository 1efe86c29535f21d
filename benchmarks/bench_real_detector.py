"""Mapping with the real COCO detectors at 640x480 on one core: frames/s per stage.

    .venv/bin/python benchmarks/bench_real_detector.py [--seed 0] [--frames 40] [--dataset DIR]
        [--weights ../shared/weights] [--detectors yolo-fastest centernet]

Records ``capnav sim --seed S --width 640 --height 480 --frames N`` (or reads ``--dataset``),
then maps the same frames with each real detector and, as the reference on the same run, with
the ``sim`` detector (default noise, seed 0). Everything runs on one thread (numba, BLAS,
onnxruntime and OpenCV limited to 1). Stages, CPU milliseconds per frame (``process_time``, so
a busy shared machine does not inflate them): the detector model (resize, inference, decoding,
NMS), its depth masks, the dense encoder + voxel fusion, and lifting + tracking + memory. The
target is >= 5 frames/s on one core including the detector.
"""

from __future__ import annotations

import os

for _v in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import logging  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

from bench_common import REPO, WEIGHT_FOLDERS, table  # noqa: E402


class _Clock:
    """CPU seconds per named stage, collected by wrapping methods of live objects."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}

    def wrap(self, obj: Any, method: str, stage: str) -> None:
        fn: Callable[..., Any] = getattr(obj, method)
        self.seconds.setdefault(stage, 0.0)

        def timed(*a: Any, **kw: Any) -> Any:
            t0 = time.process_time()
            try:
                return fn(*a, **kw)
            finally:
                self.seconds[stage] += time.process_time() - t0

        setattr(obj, method, timed)


def run(name: str, frames: list[Any], weights: Path) -> tuple[dict[str, float], float, float, int, int]:
    """Map ``frames`` with detector ``name``; (CPU seconds per stage, total CPU, wall, detections, objects)."""
    from capnav.language import create_embedder
    from capnav.mapping import Mapper, MapperConfig
    from capnav.perception import create_detector, create_encoder

    if name == "sim":
        det = create_detector("sim", noise="default", seed=0)
    else:
        det = create_detector(name, model_dir=str(weights / WEIGHT_FOLDERS[name]), threads=1)
    enc = create_encoder("label-embedding", embedder=create_embedder("minilm"))
    Mapper(MapperConfig(), det, enc).integrate(frames[0])  # warm: numba, embeddings of the labels, the model
    m = Mapper(MapperConfig(), det, enc)
    clock = _Clock()
    if name == "sim":
        clock.wrap(det, "detect", "detector")
    else:
        clock.wrap(det, "boxes", "detector")
        clock.wrap(det, "masks", "masks")
    clock.wrap(enc, "encode_indexed", "fusion")
    clock.wrap(m.voxels, "integrate_frame", "fusion")
    n_det = 0
    inner = det.detect

    def counted(frame: Any) -> Any:
        nonlocal n_det
        out = inner(frame)
        n_det += len(out)
        return out

    det.detect = counted  # type: ignore[method-assign]
    w0, t0 = time.perf_counter(), time.process_time()
    for f in frames:
        m.integrate(f)
    total, wall = time.process_time() - t0, time.perf_counter() - w0
    cmap = m.finish()
    stages = dict(clock.seconds)
    stages["tracking"] = total - sum(stages.values())  # lifting, SG3DTracker, memory, validation
    return stages, total, wall, n_det, len(cmap.objects)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--frames", type=int, default=40)
    ap.add_argument("--dataset", type=Path, default=None, help="an existing 640x480 recording instead")
    ap.add_argument("--weights", type=Path, default=Path(os.environ.get("CAPNAV_SHARED", REPO.parent / "shared"))
                    / "weights")
    ap.add_argument("--detectors", nargs="+", default=list(WEIGHT_FOLDERS), choices=list(WEIGHT_FOLDERS))
    args = ap.parse_args()
    logging.getLogger("capnav").setLevel(logging.ERROR)  # pose jumps of a subsampled pass are expected here

    from capnav.io.dataset import DatasetReader

    with tempfile.TemporaryDirectory() as tmp:
        ds = args.dataset
        if ds is None:
            from capnav.cli import app

            ds = Path(tmp) / "rec"
            t0 = time.perf_counter()
            try:
                app(["sim", "--seed", str(args.seed), "--width", "640", "--height", "480", "--frames",
                     str(args.frames), "-o", str(ds)], standalone_mode=False)
            except SystemExit:
                pass
            print(f"recorded capnav sim --seed {args.seed} --width 640 --height 480 --frames {args.frames} "
                  f"in {time.perf_counter() - t0:.0f} s")
        reader = DatasetReader(ds)
        frames = [reader.frame(i) for i in range(min(len(reader), args.frames))]
    h, w = frames[0].shape
    rows = []
    for name in ["sim", *args.detectors]:
        stages, total, wall, n_det, n_obj = run(name, frames, args.weights)
        n = len(frames)
        ms = {k: f"{1000 * v / n:.1f}" for k, v in stages.items()}
        rows.append([name + (" (reference)" if name == "sim" else ""), ms.get("detector", "-"), ms.get("masks", "-"),
                     ms["fusion"], ms["tracking"], f"{1000 * total / n:.1f}", f"{n / total:.1f}", f"{n / wall:.1f}",
                     f"{n_det / n:.1f}", str(n_obj)])
    table(f"mapping {len(frames)} frames at {w}x{h}, one thread (CPU ms per frame; target >= 5 frames/s)",
           ["detector", "model", "masks", "encoder+fusion", "lift+track", "total", "frames/s CPU", "frames/s wall",
            "detections/frame", "objects"], rows)
    print(f"\nload average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores "
          "(wall clock suffers from it, CPU time not)")


if __name__ == "__main__":
    main()
