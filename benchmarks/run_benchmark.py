"""Where the benchmark's time goes, and whether the full default run fits its 60-minute budget.

Runs the whole pipeline on ONE apartment (simulator, exploration stream, map, captions, every
method on both protocols) in this process, measures CPU seconds per stage and per subgoal, and
projects the full default benchmark (10 apartments, 2 workers) from it. The reference column is
the acceptance budget (60 min on a 2-core machine). CPU time, not wall time, is measured so that
other load on the machine does not distort the projection.

    .venv/bin/python benchmarks/run_benchmark.py [--methods capnav,vlmaps] [--episodes 3] [--seed 0]
"""

from __future__ import annotations

import argparse
import resource
import tempfile
import time
from collections import Counter

from capnav.eval.method import load_methods
from capnav.eval.scene_task import DEFAULT_METHODS, EvalConfig, SceneTask, run_scene

BUDGET_MIN = 60.0
FULL_SCENES, FULL_EPISODES, WORKERS = 10, 9, 2


def cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--methods", default="all", help="comma-separated, or 'all' (every registered method)")
    ap.add_argument("--episodes", type=int, default=3, help="episodes per protocol on the measured apartment")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    names = DEFAULT_METHODS + tuple(m for m in load_methods() if m not in DEFAULT_METHODS) \
        if args.methods == "all" else tuple(m.strip() for m in args.methods.split(","))
    cfg = EvalConfig(scenes=1, episodes_per_scene=args.episodes, seed=args.seed, methods=names)
    with tempfile.TemporaryDirectory() as tmp:
        c0, w0 = cpu(), time.perf_counter()
        res = run_scene(SceneTask(cfg, cfg.scene_seeds()[0], tmp))
        total_cpu, total_wall = cpu() - c0, time.perf_counter() - w0
    subgoals = Counter(r["method"] for r in res["records"])
    t = res["timings"]
    shared = sum(v for k, v in t.items() if not k.startswith("method:"))
    scale = FULL_EPISODES / args.episodes  # per-apartment method time grows with episodes; shared work does not
    per_scene = shared + scale * sum(v for k, v in t.items() if k.startswith("method:"))
    # wall-clock stage timings are rescaled to CPU seconds with this run's CPU/wall ratio
    ratio = total_cpu / max(total_wall, 1e-9)
    projected_min = ratio * per_scene * FULL_SCENES / WORKERS / 60.0
    print(f"one apartment (seed {cfg.scene_seeds()[0]}), {args.episodes} episodes per protocol: "
          f"{total_wall:.1f} s wall, {total_cpu:.1f} s CPU (CPU/wall {ratio:.2f})\n")
    print(f"| {'stage':<28} | {'seconds':>8} | {'per subgoal (ms)':>16} |")
    print(f"|{'-' * 30}|{'-' * 10}|{'-' * 18}|")
    for k, v in t.items():
        n = subgoals.get(k.removeprefix("method:"), 0)
        per = f"{1e3 * v / n:.0f}" if k.startswith("method:") and n else ""
        print(f"| {k:<28} | {v:>8.1f} | {per:>16} |")
    print(f"\n| {'full default benchmark':<30} | {'ours':>10} | {'budget (reference)':>18} |")
    print(f"|{'-' * 32}|{'-' * 12}|{'-' * 20}|")
    print(f"| {'projected minutes, 2 workers':<30} | {projected_min:>10.1f} | {BUDGET_MIN:>18.1f} |")
    for k, v in t.items():
        if k.startswith("method:"):
            share = ratio * scale * v * FULL_SCENES / WORKERS / 60.0
            print(f"| {'  of which ' + k.removeprefix('method:'):<30} | {share:>10.1f} | {'':>18} |")


if __name__ == "__main__":
    main()
