"""Retrieval accuracy of the full offline pipeline: sim -> map -> describe -> query.

For each apartment seed: record the exploration pass (``capnav sim`` defaults), map it with the
simulator detector at its default noise, describe the map with the offline captioner and the
MiniLM embedder, then ask generated instructions (``capnav.sim.instructions``) and score the
answers against the scene truth. A chosen object counts as an instance when most of its points
lie inside that instance's box (the rule of ``capnav.eval.map_quality``).

    .venv/bin/python benchmarks/eval_retrieval.py --seeds 1 2 3 --per-kind 20 --work /tmp/capnav-eval
"""

from __future__ import annotations

import argparse
import json
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

from capnav.eval.map_quality import inside_box
from capnav.io.dataset import DatasetReader
from capnav.io.mapfile import load_map, save_map
from capnav.language import create_captioner, create_embedder, describe_map
from capnav.mapping import MapperConfig, map_dataset
from capnav.mapping.cmap import CapNavMap
from capnav.mapping.objects import MapObject
from capnav.perception import create_detector, create_encoder
from capnav.retrieval import RetrievalConfig, Retriever, create_verifier
from capnav.sim.instructions import KINDS, Instruction, generate_instructions
from capnav.sim.manifest import SceneManifest
from capnav.sim.record import record_dataset

TARGETS = {"attribute": 0.90, "superlative": 0.90, "relation": 0.90, "room": 0.90, "category": 0.95,
           "closest": 0.95, "absent": 0.90}


def build(seed: int, work: Path, detector_seed: int = 0) -> tuple[CapNavMap, SceneManifest]:
    data, mpath = work / f"apt{seed}", work / f"apt{seed}.capnav"
    if not (data / "manifest.json").exists():
        print(record_dataset(seed=seed, out=data, overwrite=True, progress=False))
    if not mpath.exists():
        emb = create_embedder("minilm")
        det = create_detector("sim", noise="default", seed=detector_seed)
        cmap = map_dataset(data, det, create_encoder("label-embedding", embedder=emb), MapperConfig(), progress=False)
        save_map(cmap, mpath)
    cmap = load_map(mpath)
    t = time.perf_counter()
    rep = describe_map(cmap, DatasetReader(data), create_captioner("offline"), create_embedder("minilm"),
                       progress=False)
    print(f"seed {seed}: {len(cmap.objects)} objects described in {time.perf_counter() - t:.1f} s {rep.seconds}")
    return cmap, SceneManifest.load(data / "manifest.json")


def instance_of(obj: MapObject, manifest: SceneManifest) -> int | None:
    if len(obj.points) == 0:
        return None
    shares = [float(inside_box(obj.points, g, 0.1).mean()) for g in manifest.objects]
    j = int(np.argmax(shares))
    return manifest.objects[j].id if shares[j] >= 0.3 else None


def score(ins: Instruction, chosen: MapObject | None, manifest: SceneManifest) -> bool:
    if ins.kind == "absent":
        return chosen is None
    if chosen is None:
        return False
    inst = instance_of(chosen, manifest)
    if ins.kind == "category":
        return inst is not None and manifest.object(inst).category == ins.category
    return inst in ins.targets


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    ap.add_argument("--per-kind", type=int, default=20)
    ap.add_argument("--instruction-seed", type=int, default=0)
    ap.add_argument("--work", type=Path, default=Path("/tmp/capnav-eval"))
    ap.add_argument("--verifier", default="offline")
    ap.add_argument("--no-heuristic", action="store_true", help="ablation: no attribute heuristic")
    ap.add_argument("--show-failures", action="store_true")
    ap.add_argument("--json", type=Path, default=None, help="write per-instruction results here")
    args = ap.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    hits: dict[str, list[bool]] = defaultdict(list)
    mapped_hits: dict[str, list[bool]] = defaultdict(list)
    rows = []
    lat: list[float] = []
    for seed in args.seeds:
        cmap, manifest = build(seed, args.work)
        emb = create_embedder("minilm")
        cfg = RetrievalConfig(use_verifier=args.verifier != "none", use_attribute_heuristic=not args.no_heuristic)
        r = Retriever(cmap, emb, verifier=create_verifier(args.verifier), config=cfg)
        seen = {instance_of(o, manifest) for o in cmap.objects} - {None}
        for ins in generate_instructions(manifest, per_kind=args.per_kind, seed=args.instruction_seed + seed):
            t = time.perf_counter()
            res = r.query(ins.text, robot_xy=ins.robot_xy)
            lat.append(time.perf_counter() - t)
            ok = score(ins, res.chosen, manifest)
            hits[ins.kind].append(ok)
            if ins.kind == "absent" or (ins.kind == "category" and seen & set(ins.targets)) or \
                    set(ins.targets) <= seen:
                mapped_hits[ins.kind].append(ok)
            got = None if res.chosen is None else instance_of(res.chosen, manifest)
            rows.append({"seed": seed, **ins.to_dict(), "ok": ok, "chosen_instance": got,
                         "mapped": set(ins.targets) <= seen,
                         "caption": None if res.chosen is None else res.chosen.caption, "reason": res.reason})
            if args.show_failures and not ok:
                print(f"  FAIL s{seed} {ins.kind:11s} {ins.text!r} targets={ins.targets} got={got} "
                      f"| {res.reason[:220]}")
    print(f"\nseeds {args.seeds}, instruction seed {args.instruction_seed}+scene seed, verifier {args.verifier}, "
          f"heuristic {'off' if args.no_heuristic else 'on'}")
    print("all: every instruction; mapped: only those whose target instance(s) the map contains")
    print(f"{'kind':12s} {'n':>4s} {'all':>7s} {'n':>4s} {'mapped':>7s} {'target':>7s}")
    for k in KINDS:
        v, w = hits.get(k, []), mapped_hits.get(k, [])
        if v:
            print(f"{k:12s} {len(v):4d} {np.mean(v):7.1%} {len(w):4d} {np.mean(w) if w else float('nan'):7.1%} "
                  f"{TARGETS[k]:7.0%}")
    single = [x for k in ("attribute", "superlative", "relation", "room") for x in hits.get(k, [])]
    msingle = [x for k in ("attribute", "superlative", "relation", "room") for x in mapped_hits.get(k, [])]
    print(f"{'singled-out':12s} {len(single):4d} {np.mean(single):7.1%} {len(msingle):4d} {np.mean(msingle):7.1%} "
          f"{0.9:7.0%}")
    print(f"query latency p50 {np.percentile(lat, 50) * 1e3:.1f} ms, p95 {np.percentile(lat, 95) * 1e3:.1f} ms")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
