"""Requests on a simulated user's recording: the path of a robot owner's own data, scored.

A Sweet Home 3D apartment (``capnav sim --furniture sh3d --surface-items --depth-noise``) is
exported as another tool's recording in a tilted world (``--export tum --tilt R,P,Y``), imported
with no option (``capnav import auto``: layout, up and floor found from the data), mapped with
each real COCO detector (``capnav map --detector``), captioned (``capnav caption``), and asked the
requests of a file written by hand from the apartment's manifest (jsonl: ``seed``,
``instruction``, ``accept_ids``: manifest ids, empty = nothing fits, refuse). An answer is right
when the chosen object's centre lies nearest (in x, y) to an accepted instance's, or within
half its footprint's diagonal of one; truth is moved into the imported map's frame by the poses
(imported pose = M x recorded pose, recorded = tilt x simulator pose), for scoring only.

    PYTHONPATH=src .venv/bin/python benchmarks/eval_recording_requests.py \\
        benchmarks/own_phrasings/own_recording_47.jsonl [--width 640 --height 480]
        [--tilt 5,-20,30] [--detectors centernet yolo-fastest] [--workdir DIR] [--failures]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from capnav.api import CapNav
from capnav.io.dataset import DatasetReader
from capnav.io.export import tilt_matrix
from capnav.io.importer import import_recording
from capnav.io.layouts import open_recording
from capnav.sim.record import record_dataset

CLI = [sys.executable, "-m", "capnav.cli"]


def prepare(seed: int, args: argparse.Namespace, work: Path) -> tuple[Path, dict[int, dict[str, object]]]:
    """The imported recording of apartment ``seed`` and its truth in the recording's map frame."""
    src, ds_dir = work / f"rec{seed}", work / f"rec{seed}-imported"
    if not (src / "manifest.json").exists():
        record_dataset(seed=seed, out=src, width=args.width, height=args.height, furniture="sh3d",
                       surface_items=True, depth_noise=True, export=args.layout, tilt=args.tilt, progress=True)
    rec, _, _ = open_recording(src)
    if not (ds_dir / "meta.json").exists():
        import_recording(rec, ds_dir, progress=True)
    ds = DatasetReader(ds_dir)
    recorded = {f.source_index: f.T_wc for f in rec.frames}
    pairs = [(T, recorded[s[1]]) for T, s in zip(ds.poses, ds.meta["meta"]["import"]["frames"], strict=True)]
    W = tilt_matrix(args.tilt)
    M = pairs[0][0] @ np.linalg.inv(pairs[0][1]) @ W  # simulator world -> imported map frame
    worst = max(float(np.abs(T - M @ np.linalg.inv(W) @ R).max()) for T, R in pairs)
    if worst > 1e-3:
        raise SystemExit(f"the import is not one rigid transform of the recording (residual {worst:.3g})")
    manifest = json.loads((src / "manifest.json").read_text())
    truth = {}
    for o in manifest["objects"] + manifest.get("items", []):
        c = M[:3, :3] @ np.asarray(o["center"], dtype=np.float64) + M[:3, 3]
        truth[int(o["id"])] = {"category": o["category"], "xy": c[:2], "reach": 0.5 * float(np.hypot(*o["size"][:2]))}
    return ds_dir, truth


def right(chosen_xy: np.ndarray, accept: list[int], truth: dict[int, dict[str, object]]) -> bool:
    d = {i: float(np.linalg.norm(np.asarray(t["xy"]) - chosen_xy)) for i, t in truth.items()}
    nearest = min(d, key=lambda i: d[i])
    return nearest in accept or any(d[i] <= float(truth[i]["reach"]) for i in accept)  # type: ignore[arg-type]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("requests", type=Path)
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=480)
    ap.add_argument("--layout", default="tum")
    ap.add_argument("--tilt", default="5,-20,30")
    ap.add_argument("--detectors", nargs="+", default=["centernet", "yolo-fastest"])
    ap.add_argument("--workdir", type=Path, default=Path("data/recording_requests"))
    ap.add_argument("--failures", action="store_true")
    args = ap.parse_args()
    rows = [json.loads(line) for line in args.requests.read_text().splitlines() if line.strip()]
    args.workdir.mkdir(parents=True, exist_ok=True)
    table: dict[str, list[int]] = {}
    for seed in sorted({int(r["seed"]) for r in rows}):
        ds_dir, truth = prepare(seed, args, args.workdir)
        for det in args.detectors:
            mp = args.workdir / f"rec{seed}-{det}.capnav"
            t0 = time.time()
            if not mp.exists():
                subprocess.run([*CLI, "map", str(ds_dir), "-o", str(mp), "--detector", det], check=True)
            cap = subprocess.run([*CLI, "caption", str(mp), "--dataset", str(ds_dir)], capture_output=True, text=True)
            if cap.returncode:
                raise SystemExit(f"capnav caption {mp} failed: {cap.stderr.strip()[-400:]}")
            nav = CapNav.open(mp)
            for r in (r for r in rows if int(r["seed"]) == seed):
                a = nav.ask(r["instruction"])
                accept = [int(i) for i in r["accept_ids"]]
                ok = (not a.found) if not accept else bool(
                    a.object is not None and right(np.asarray(a.object.centroid[:2]), accept, truth))
                table.setdefault(det, [0, 0, 0, 0])
                t = table[det]
                t[0] += ok
                t[1] += 1
                t[2] += int(ok and not accept)
                t[3] += not accept
                if args.failures and not ok:
                    said = a.object.category if a.object is not None else "not found"
                    print(f"  [{det}] {r['instruction']!r}: {said}; {a.reason[:160]}")
            print(f"seed {seed} {det}: map + caption + requests {time.time() - t0:.0f} s", flush=True)
    print("\n| detector | right | absent refused |\n|---|---|---|")
    for det, (hits, n, ab_ok, ab) in table.items():
        print(f"| {det} | {hits}/{n} | {ab_ok}/{ab} |")


if __name__ == "__main__":
    main()
