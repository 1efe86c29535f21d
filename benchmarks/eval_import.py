"""Import round trip: simulated recordings exported in each layout in a randomly tilted world, read back.

For every seed and layout, ``capnav sim --export LAYOUT --tilt R,P,Y`` (the tilt drawn from the seed:
roll and pitch within +-60 degrees, any yaw) writes the exploration pass; the layout is recognised,
imported with no option, and compared with the truth the export implies (the recorded poses are
``W @ T``): whether up was found, its angle to the true up, the camera height error (median over
frames, metres), the reprojection check's verdict and agreement, and the import's CPU time.

    .venv/bin/python benchmarks/eval_import.py [--seeds 0 1 2 3 4] [--layouts open3d tum 3dmatch scannet]
        [--frames 40] [--stride 3] [--width 160] [--height 120] [--depth-noise]
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from capnav.core.errors import InputError
from capnav.io.dataset import DatasetReader
from capnav.io.export import EXPORT_LAYOUTS, tilt_matrix
from capnav.io.importer import import_recording
from capnav.io.layouts import open_recording
from capnav.sim.record import record_dataset


def one(seed: int, layout: str, args: argparse.Namespace, work: Path) -> dict[str, object]:
    rng = np.random.default_rng(1000 + seed)
    tilt = f"{rng.uniform(-60, 60):.1f},{rng.uniform(-60, 60):.1f},{rng.uniform(-180, 180):.1f}"
    src, out = work / f"{layout}-{seed}", work / f"{layout}-{seed}-ds"
    record_dataset(seed=seed, out=src, frames=args.frames, stride=args.stride, width=args.width,
                   height=args.height, progress=False, export=layout, tilt=tilt, depth_noise=args.depth_noise)
    W = tilt_matrix(tilt)
    t0 = time.process_time()
    rec, lay, _ = open_recording(src)
    truth_h = {f.source_index: (np.linalg.inv(W) @ f.T_wc)[2, 3] for f in rec.frames}
    row: dict[str, object] = {"seed": seed, "layout": layout, "tilt": tilt, "recognised": lay.name == layout}
    try:
        rep = import_recording(rec, out, progress=False)
    except InputError as e:
        row.update(ok=False, why=str(e)[:120], cpu_s=time.process_time() - t0)
        return row
    ds = DatasetReader(out)
    up = np.asarray(rep.alignment.info["up_in_recording"])
    true_up = W[:3, :3] @ np.array([0.0, 0.0, 1.0])
    cons = rep.meta["consistency"]
    row.update(ok=True, up_err_deg=float(np.degrees(np.arccos(np.clip(up @ true_up, -1, 1)))),
               height_err_m=float(np.median([abs(T[2, 3] - truth_h[src[1]]) for T, src in
                                             zip(ds.poses, ds.meta["meta"]["import"]["frames"], strict=True)])),
               written=rep.written, skipped=rep.skipped.counts(),
               confidence=rep.alignment.info["confidence"], check=cons["verdict"],
               agreement=cons["agreement"].get("as recorded", 0.0), cpu_s=time.process_time() - t0)
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3, 4])
    ap.add_argument("--layouts", nargs="+", default=list(EXPORT_LAYOUTS), choices=EXPORT_LAYOUTS)
    ap.add_argument("--frames", type=int, default=40)
    ap.add_argument("--stride", type=int, default=3)
    ap.add_argument("--width", type=int, default=160)
    ap.add_argument("--height", type=int, default=120)
    ap.add_argument("--depth-noise", action="store_true", help="consumer RGB-D depth noise (seeded)")
    args = ap.parse_args()
    work = Path(tempfile.mkdtemp(prefix="capnav-eval-import-"))
    rows = []
    try:
        for seed in args.seeds:
            for layout in args.layouts:
                rows.append(one(seed, layout, args, work))
                r = rows[-1]
                print(f"seed {seed} {layout:8s} tilt {r['tilt']:>20s}: " + (
                    f"up {r['up_err_deg']:.2f} deg off, height {100 * r['height_err_m']:.1f} cm off, "  # type: ignore[operator]
                    f"confidence {r['confidence']:.2f}, check {r['check']} ({100 * r['agreement']:.0f}%), "  # type: ignore[operator]
                    f"{r['cpu_s']:.1f} s CPU, {r['written']} frames" + (f" (skipped {r['skipped']})" if r["skipped"]
                                                                           else "")
                    if r["ok"] else f"REFUSED: {r['why']}"), flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    ok = [r for r in rows if r["ok"]]
    print(f"\n{len(ok)}/{len(rows)} imported with up found; recognised {sum(bool(r['recognised']) for r in rows)}"
          f"/{len(rows)}; median up error {np.median([r['up_err_deg'] for r in ok]):.2f} deg, worst "
          f"{max(r['up_err_deg'] for r in ok):.2f}; median height error "  # type: ignore[type-var]
          f"{100 * np.median([r['height_err_m'] for r in ok]):.1f} cm" if ok else "none imported")


if __name__ == "__main__":
    main()
