"""Identity across visits: does `map --update` keep an object's id when it stays or is carried
elsewhere, retire what was thrown out and give newcomers new ids, with a real detector as well as
the simulator's? The simulator's detector hands out no ids that survive a visit, and a COCO model
none at all, so identity can only come from position, size, appearance and caption.

    .venv/bin/python benchmarks/eval_update_identity.py [--seeds 0 1] [--detector yolo-fastest]
        [--furniture sh3d] [--depth-noise] [--changes moved=3,removed=2,added=2] [--stride 2]

Per apartment: visit 1 recorded and mapped, visit 2 (after the seeded changes) recorded and fused
into that map with ``update_map``; both maps are matched to the visits' truth by their points
(``capnav.eval.update_identity``: evaluation only). Printed per change class: the outcomes, and
how many are right (unchanged and moved: the same id on the instance; removed: retired; added: a
new id on it). Instances the first map never held (a COCO model has no bookshelf) are left out;
newcomers of a category the detector has no class for are listed as undetectable, not counted.
"""

from __future__ import annotations

import os

for _v in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402
from collections import Counter  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_common import REPO, WEIGHT_FOLDERS, table  # noqa: E402


def _detector(name: str, weights: Path, seed: int) -> Any:
    from capnav.perception import create_detector

    if name == "sim":
        return create_detector("sim", noise="default", seed=seed)
    return create_detector(name, model_dir=str(weights / WEIGHT_FOLDERS[name]), threads=1)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1], help="apartments (simulator seeds)")
    ap.add_argument("--changes", default="moved=3,removed=2,added=2")
    ap.add_argument("--detector", default="yolo-fastest", choices=["sim", *WEIGHT_FOLDERS])
    ap.add_argument("--weights", type=Path, default=Path(os.environ.get("CAPNAV_SHARED", REPO.parent / "shared"))
                    / "weights")
    ap.add_argument("--furniture", default="primitives", choices=["primitives", "sh3d"])
    ap.add_argument("--depth-noise", action="store_true")
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    ap.add_argument("--stride", type=int, default=2)
    ap.add_argument("--cache", type=Path, default=Path("data/eval-update-identity"))
    ap.add_argument("--json", type=Path, help="also write every instance's outcome here")
    args = ap.parse_args()

    from capnav.eval.update_identity import RIGHT, UNCOUNTED, identity_report
    from capnav.io.dataset import DatasetReader
    from capnav.language import create_embedder
    from capnav.mapping import map_dataset
    from capnav.mapping.update import update_map
    from capnav.perception import create_encoder
    from capnav.sim.changes import ChangeSpec
    from capnav.sim.manifest import SceneManifest
    from capnav.sim.record import record_dataset

    spec = ChangeSpec.parse(args.changes)
    enc = create_encoder("label-embedding", embedder=create_embedder("minilm"))
    totals: dict[str, Counter[str]] = {}
    every: list[dict[str, Any]] = []
    rows: list[list[str]] = []
    for seed in args.seeds:
        noise = "-noise" if args.depth_noise else ""
        tag = f"apt{seed}-{args.furniture}{noise}-{args.width}x{args.height}-s{args.stride}"
        folders = []
        for k in (1, 2):
            d = args.cache / tag / f"visit{k}"
            if not (d / "meta.json").is_file():
                record_dataset(seed, d, stride=args.stride, width=args.width, height=args.height,
                               furniture=args.furniture, depth_noise=args.depth_noise, progress=False, visit=k,
                               changes=spec if k > 1 else None, change_seed=seed, overwrite=d.exists())
            folders.append(d)
        manifests = [SceneManifest.model_validate_json((d / "manifest.json").read_text()) for d in folders]
        before = map_dataset(DatasetReader(folders[0]), _detector(args.detector, args.weights, seed), enc,
                             progress=False)
        after, upd = update_map(before, DatasetReader(folders[1]), _detector(args.detector, args.weights, seed + 1),
                                enc, progress=False)
        rep = identity_report(before, after, manifests[0], manifests[1])
        print(f"apartment {seed}: map 1 {len(before.objects)} objects; update: {upd.summary()}", flush=True)
        for cls in RIGHT:
            ok, n = rep.right(cls)
            rows.append([str(seed), cls, f"{ok}/{n}", ", ".join(f"{k} {v}" for k, v in sorted(rep.counts.get(cls,
                                                                                                       {}).items()))])
            totals.setdefault(cls, Counter()).update(rep.counts.get(cls, Counter()))
        every += [{"seed": seed, **r} for r in rep.per_instance]
    for cls in RIGHT:
        c = totals.get(cls, Counter())
        counted = sum(v for o, v in c.items() if o not in UNCOUNTED)
        rows.append(["all", cls, f"{sum(c[o] for o in RIGHT[cls])}/{counted}",
                     ", ".join(f"{k} {v}" for k, v in sorted(c.items()))])
    table(f"Identity across visits, detector {args.detector}, furniture {args.furniture}"
          f"{', depth noise' if args.depth_noise else ''}, {args.width}x{args.height} stride {args.stride}, "
          f"changes {args.changes} (right = unchanged/moved: same id; removed: retired; added: a new id)",
          ["apartment", "class", "right", "outcomes"], rows)
    if args.json:
        args.json.write_text(json.dumps(every, indent=1))


if __name__ == "__main__":
    from capnav.core.errors import CapNavError

    try:
        main()
    except CapNavError as e:  # a missing weights folder, a recording that cannot be read: said, no traceback
        sys.exit(f"eval_update_identity.py: {e}")
