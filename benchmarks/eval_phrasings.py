"""Top-1 retrieval on a file of hand-written instructions, in one process, with every goal of a
request of several scored: per kind, overall, absent refused, and the requests whose goals are
all right (a ``then`` field holds the second goal's ids).

    python benchmarks/eval_phrasings.py INSTRUCTIONS.jsonl --workdir DIR [--kind K ...] [--failures]

Reads the maps and manifests the phrasing scorer builds (``DIR/aptS.capnav`` and
``DIR/aptS/manifest.json``, from ``capnav sim --seed S``, ``capnav map``, ``capnav caption``) and
asks each instruction through ``query_goals`` (what ``capnav query`` runs), so a whole set takes
seconds instead of one process per instruction. The rule is the scorer's: a chosen object is
right when its position lies inside or within 0.5 m of an accepted instance's footprint and no
other instance's footprint is nearer; an absent target is right when refused. The manifest is the
simulator's truth, read here to judge only."""

from __future__ import annotations

import argparse
import json
from collections import defaultdict
from pathlib import Path

import numpy as np

TOLERANCE_M = 0.5


def footprint_distance(p: np.ndarray, poly: list[list[float]]) -> float:
    """0 inside the polygon, else the distance to its nearest edge."""
    P = np.asarray(poly, dtype=np.float64)
    x, y = p
    inside = False
    for (x1, y1), (x2, y2) in zip(P, np.roll(P, -1, axis=0), strict=True):
        if (y1 > y) != (y2 > y) and x < (x2 - x1) * (y - y1) / (y2 - y1) + x1:
            inside = not inside
    if inside:
        return 0.0
    a, b = P, np.roll(P, -1, axis=0)
    d = b - a
    t = np.clip(np.einsum("ij,ij->i", p - a, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-12), 0, 1)
    return float(np.min(np.linalg.norm(a + t[:, None] * d - p, axis=1)))


def right(accept: list[int], answer: dict | None, manifest: dict) -> bool:
    found = bool(answer and answer.get("found"))
    if not accept:
        return not found
    if not found or not answer or not answer.get("chosen"):
        return False
    p = np.asarray(answer["chosen"]["position"][:2], dtype=np.float64)
    dists = sorted((footprint_distance(p, o["footprint"]), o["id"] not in accept) for o in manifest["objects"])
    best_accepted = min((d for d, other in dists if not other), default=np.inf)
    return best_accepted <= TOLERANCE_M and not dists[0][1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("instructions", type=Path)
    ap.add_argument("--workdir", type=Path, required=True)
    ap.add_argument("--kind", action="append", help="only this kind (repeatable)")
    ap.add_argument("--failures", action="store_true", help="print each wrong answer's reason")
    args = ap.parse_args()

    from capnav.core.errors import CapNavError
    from capnav.io.mapfile import load_map
    from capnav.language import create_embedder
    from capnav.retrieval import RetrievalConfig, Retriever, create_verifier
    from capnav.retrieval.sequence import query_goals

    items = [json.loads(line) for line in args.instructions.read_text().splitlines() if line.strip()]
    items = [i for i in items if not args.kind or i["kind"] in args.kind]
    emb = create_embedder("minilm")
    apts: dict[int, tuple[Retriever, dict]] = {}
    per: dict[str, list[int]] = defaultdict(lambda: [0, 0])
    absent, goals_all = [0, 0], [0, 0]
    for it in items:
        seed = int(it["seed"])
        if seed not in apts:
            cmap = load_map(args.workdir / f"apt{seed}.capnav", voxels=False)
            manifest = json.loads((args.workdir / f"apt{seed}" / "manifest.json").read_text())
            apts[seed] = (Retriever(cmap, emb, create_verifier("offline"), RetrievalConfig()), manifest)
        r, manifest = apts[seed]
        robot = tuple(it["robot"]) if it.get("robot") else None
        try:
            seq = json.loads(json.dumps(query_goals(r, it["instruction"], robot_xy=robot).to_dict(), default=str))
        except CapNavError as e:  # refused input: counted wrong, as the scorer counts a failed query
            seq = {"found": False, "reason": f"error: {e}"}
        ok = right(it["accept_ids"], seq, manifest)
        per[it["kind"]][0] += ok
        per[it["kind"]][1] += 1
        if not it["accept_ids"]:
            absent[0] += ok
            absent[1] += 1
        if it.get("then"):
            goals = seq.get("goals") or []
            both = ok and len(goals) > 1 and right(it["then"], goals[1], manifest)
            goals_all[0] += both
            goals_all[1] += 1
            if args.failures and ok and not both:
                second = goals[1].get("reason", "") if len(goals) > 1 else f"{len(goals)} goal(s) read"
                print(f"[{it['kind']}, second goal] {seed} {it['instruction']!r}: {second[:300]}")
        if args.failures and not ok:
            print(f"[{it['kind']}] {seed} {it['instruction']!r}: {seq.get('reason', '')[:300]}")
    print("| kind | n | top-1 |\n|---|---:|---:|")
    for k, (c, n) in sorted(per.items()):
        print(f"| {k} | {n} | {c} |")
    c, n = sum(v[0] for v in per.values()), sum(v[1] for v in per.values())
    print(f"\noverall top-1: {c}/{n} = {100 * c / max(n, 1):.1f}%")
    print(f"absent refused: {absent[0]}/{absent[1]}")
    if goals_all[1]:
        print(f"requests of several goals with every goal right: {goals_all[0]}/{goals_all[1]}")


if __name__ == "__main__":
    main()
