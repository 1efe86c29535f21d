"""What a map update costs: CPU time beside mapping the same recording from scratch, and memory
over 1, 3 and 10 recordings of one changing home.

    .venv/bin/python benchmarks/bench_update.py [--seed 0] [--visits 10] [--detector sim|yolo-fastest]
        [--changes moved=3,removed=2,added=2] [--cache data/bench-update]

Apartment ``--seed`` is recorded ``--visits`` times (visit 1 as generated, visit k > 1 after its
own seeded changes to visit 1's home: things move away and back, lamps go and come). Visit 1 is
mapped; every later visit updates the map of the visits before it (``update_map``), and is also
mapped from scratch on the same frames with the same detector. Times are process CPU seconds,
detection included (the update runs the detector only where something is new). Memory: the map's
arrays in memory (points, colours, voxels, trajectory) and its file, after 1, 3 and 10 recordings,
beside the number of present and retired objects: what grows is the changed surface (retired
objects keep their points) and the camera path, not a copy of the house per recording.
"""

from __future__ import annotations

import os

for _v in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_common import REPO, WEIGHT_FOLDERS, table  # noqa: E402


def _detector(name: str, weights: Path) -> Any:
    from capnav.perception import create_detector

    if name == "sim":
        return create_detector("sim", noise="default", seed=0)
    return create_detector(name, model_dir=str(weights / WEIGHT_FOLDERS[name]), threads=1)


def _bytes(cmap: Any) -> int:
    """The map's arrays in memory: objects (present and retired), voxels, occupancy, trajectory."""
    n = 0
    for o in [*cmap.objects, *cmap.retired]:
        n += sum(np.asarray(a).nbytes for a in (o.points, o.colors, o.feature, o.footprint))
        n += np.asarray(o.embedding).nbytes if o.embedding is not None else 0
    v = cmap.voxels
    n += v.keys.nbytes + v.weights.nbytes + v.colors.nbytes + v.features.nbytes
    if cmap.occupancy is not None:
        n += cmap.occupancy.cells.nbytes
    if cmap.trajectory is not None:
        n += cmap.trajectory.frames.nbytes + cmap.trajectory.poses.nbytes
    return n


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seed", type=int, default=0, help="apartment (simulator seed); changes seeded by it too")
    ap.add_argument("--visits", type=int, default=10)
    ap.add_argument("--changes", default="moved=3,removed=2,added=2")
    ap.add_argument("--detector", default="sim", choices=["sim", *WEIGHT_FOLDERS])
    ap.add_argument("--weights", type=Path, default=Path(os.environ.get("CAPNAV_SHARED", REPO.parent / "shared"))
                    / "weights")
    ap.add_argument("--scratch", type=int, nargs="*", default=[2],
                    help="visits also mapped from scratch for the CPU comparison (default: visit 2)")
    ap.add_argument("--memory-at", type=int, nargs="*", default=[1, 3, 10])
    ap.add_argument("--width", type=int, default=160)
    ap.add_argument("--height", type=int, default=120)
    ap.add_argument("--cache", type=Path, default=Path("data/bench-update"))
    args = ap.parse_args()

    from capnav.io.dataset import DatasetReader
    from capnav.io.mapfile import save_map
    from capnav.language import create_embedder
    from capnav.mapping import map_dataset
    from capnav.mapping.update import update_map
    from capnav.perception import create_encoder
    from capnav.sim.changes import ChangeSpec
    from capnav.sim.record import record_dataset

    spec = ChangeSpec.parse(args.changes)
    enc = create_encoder("label-embedding", embedder=create_embedder("minilm"))
    folders = []
    for k in range(1, args.visits + 1):
        d = args.cache / f"apt{args.seed}-{args.width}x{args.height}" / f"visit{k}"
        if not (d / "meta.json").is_file():
            record_dataset(args.seed, d, width=args.width, height=args.height, progress=False, visit=k,
                           changes=spec if k > 1 else None, change_seed=args.seed, overwrite=d.exists())
        folders.append(d)

    t = time.process_time()
    cmap = map_dataset(DatasetReader(folders[0]), _detector(args.detector, args.weights), enc, progress=False)
    cpu_rows = [["1", f"{time.process_time() - t:.1f}", "-", "-", "-", str(len(DatasetReader(folders[0])))]]
    mem_rows: list[list[str]] = []

    def memory(k: int) -> None:
        with tempfile.TemporaryDirectory() as tmp:
            size = save_map(cmap, Path(tmp) / "m.capnav").stat().st_size
        events = sum(len(o.history) for o in [*cmap.objects, *cmap.retired])
        mem_rows.append([str(k), str(len(cmap.objects)), str(len(cmap.retired)), str(events), str(len(cmap.voxels)),
                         f"{_bytes(cmap) / 1e6:.2f}", f"{size / 1e6:.2f}"])

    if 1 in args.memory_at:
        memory(1)
    for k in range(2, args.visits + 1):
        reader = DatasetReader(folders[k - 1])
        t = time.process_time()
        cmap, rep = update_map(cmap, reader, _detector(args.detector, args.weights), enc, progress=False)
        up = time.process_time() - t
        scratch = "-"
        if k in args.scratch:
            t = time.process_time()
            map_dataset(reader, _detector(args.detector, args.weights), enc, progress=False)
            scratch = f"{time.process_time() - t:.1f}"
        cpu_rows.append([str(k), scratch, f"{up:.1f}", f"{rep.frames_detected}+{rep.frames_depth_only}",
                         f"{len(rep.moved)}/{len(rep.retired)}/{len(rep.born)}", str(rep.frames)])
        print(f"visit {k}: {rep.summary()}", flush=True)
        if k in args.memory_at:
            memory(k)
    table(f"CPU seconds per recording, apartment {args.seed}, detector {args.detector}, {args.width}x{args.height} "
          "(visit 1: mapped; later: updated, and mapped from scratch where listed)",
          ["visit", "from scratch", "update", "frames detected+depth only", "moved/retired/born", "frames"],
          cpu_rows)
    table(f"Memory after k recordings, apartment {args.seed}",
          ["recordings", "objects", "retired", "history events", "voxels", "arrays MB", "file MB"], mem_rows)


if __name__ == "__main__":
    main()
