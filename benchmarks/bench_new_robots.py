"""CPU per ask from robot positions no ask used before, in one process (no server, no sockets).

The map and instructions are bench_serve.py's (bench_query.py's synthetic, seeded 300-object map,
captioned offline). A ``CapNav`` on the map first asks every instruction from its own position
(as bench_serve's warm-up does: the readings, the verifier's judgements and whatever a map keeps
per object are made), then ``--asks`` timed asks each from a fresh seeded position: the
process's CPU time (``time.process_time``, so work on any thread of the process counts) around
``nav.ask`` (retrieval and the goal pose; the A* path is not asked). ``--fields 0`` asks without
the per-object fields (``CapNav(..., fields=False)``): the cost before them. ``--check`` also asks
every timed ask without fields on a second ``CapNav`` and counts the answers that differ.

    PYTHONPATH=src .venv/bin/python benchmarks/bench_new_robots.py [--asks 200] [--seed 0] [--fields 1] [--check]
"""

from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np

from bench_query import instructions, synthetic_map
from capnav.api import CapNav
from capnav.language import create_captioner, create_embedder, describe_map


def answer_key(ans: object) -> str:
    d = ans.to_dict()  # type: ignore[attr-defined]
    d.pop("timings_ms", None)
    return json.dumps(d, sort_keys=True, default=str)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--objects", type=int, default=300)
    ap.add_argument("--instructions", type=int, default=200)
    ap.add_argument("--asks", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--fields", type=int, default=1, help="1: per-object fields (default), 0: without")
    ap.add_argument("--check", action="store_true", help="compare every timed answer with one asked without fields")
    args = ap.parse_args()
    if args.asks < 1 or args.instructions < 1 or args.objects < 1:
        ap.error("--asks, --instructions and --objects must be at least 1")

    cmap = synthetic_map(args.objects, args.seed)
    describe_map(cmap, None, create_captioner("offline"), create_embedder("minilm"), progress=False)
    rng = np.random.default_rng(args.seed + 1)
    qs = [(text, (float(rng.uniform(0.5, 23.5)), float(rng.uniform(0.5, 17.5))))
          for text, _ in instructions(args.instructions, args.seed)]
    try:
        nav = CapNav(cmap, fields=bool(args.fields))
        ref = CapNav(cmap, fields=False) if args.check else None
    except TypeError:  # a CapNav from before the fields
        nav, ref, args.fields = CapNav(cmap), None, 0
    t = time.process_time()
    for text, xy in qs:
        nav.ask(text, robot=xy)
        if ref is not None:
            ref.ask(text, robot=xy)
    warm = time.process_time() - t
    t = time.process_time()
    prepared = nav.prepare() if args.fields else None
    prep = time.process_time() - t
    fresh = np.random.default_rng(1000 * (args.seed + 1) + 7)
    cpu, differ, walked = [], 0, 0
    prof = None
    if os.environ.get("PROFILE"):
        import cProfile

        prof = cProfile.Profile()
        prof.enable()
    for k in range(args.asks):
        text = qs[k % len(qs)][0]
        xy = (float(fresh.uniform(0.5, 23.5)), float(fresh.uniform(0.5, 17.5)))
        c = time.process_time()
        ans = nav.ask(text, robot=xy)
        cpu.append(time.process_time() - c)
        walked += ans.result.mode == "closest"
        if ref is not None:
            differ += answer_key(ans) != answer_key(ref.ask(text, robot=xy))
    if prof is not None:
        import pstats

        prof.disable()
        pstats.Stats(prof).sort_stats("cumulative").print_stats(25)
    ms = np.asarray(cpu) * 1e3
    print(f"{args.objects}-object synthetic map (seed {args.seed}), fields {'on' if args.fields else 'off'}: "
          f"{args.asks} asks from new robot positions ({walked} ranked by walking distance)")
    print(f"CPU per ask p50 {np.percentile(ms, 50):.2f} ms, mean {ms.mean():.2f}, p95 {np.percentile(ms, 95):.2f}"
          f" (process_time; warm-up {warm:.1f} s, prepare {prep:.1f} s CPU"
          + (f", {prepared}" if prepared else "") + ")")
    if ref is not None:
        print(f"answers differing from those asked without fields: {differ} of {args.asks}")
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
