"""A* time: CapNav's numba A* beside pyastar2d, libtcod and scikit-image's MCP_Geometric, in one run.

Maps: the inflated true obstacle maps of generated apartments (0.05 m cells) and an 800x800 grid
with random obstacles. Each backend solves the same seeded start/goal pairs on the same weight
grid, all 8-connected; a query's time is the smallest process CPU time of ``--repeat`` runs (the
machine is shared), and the table gives the median over queries and our time over pyastar2d's
beside issue 16's target (<= 1.5x). It checks the costs: MCP solves the same problem (step length
times mean cell weight) and must agree; pyastar2d prices a diagonal step like a straight one, so
its paths are optimal only for that metric, and we report how much longer they are under ours;
libtcod (diagonal sqrt(2)) is the reference with octile costs: on uniform grids its paths are
optimal under ours too (it prices a step by the cell entered, so on graded grids they are not).

    .venv/bin/python benchmarks/bench_astar.py [--seeds 0 1 2] [--queries 20] [--seed 0] [--repeat 3]
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from capnav.planning import BACKENDS, PlannerConfig, build_costmap

Search = Callable[[NDArray[np.float64], tuple[int, int], tuple[int, int]], tuple[NDArray[np.intp], float]]


def apartment_weights(seed: int, cfg: PlannerConfig) -> NDArray[np.float64]:
    from capnav.sim import Simulator

    sim = Simulator.from_seed(seed)
    return build_costmap(sim.obstacles(resolution=0.05), cfg).weights


def random_weights(seed: int, size: int = 800, p_block: float = 0.25) -> NDArray[np.float64]:
    rng = np.random.default_rng(seed)
    w = np.ones((size, size))
    w[rng.random((size, size)) < p_block] = np.inf
    return w


def pairs(w: NDArray[np.float64], n: int, seed: int) -> list[tuple[tuple[int, int], tuple[int, int]]]:
    """Start/goal pairs in the largest connected free region, at least half the map apart."""
    from scipy import ndimage

    lab, k = ndimage.label(np.isfinite(w), structure=np.ones((3, 3), bool))
    big = np.argmax(ndimage.sum_labels(np.ones_like(lab), lab, np.arange(1, k + 1))) + 1
    free = np.argwhere(lab == big)
    rng = np.random.default_rng(seed)
    span = 0.5 * np.hypot(*w.shape)
    out: list[tuple[tuple[int, int], tuple[int, int]]] = []
    while len(out) < n:
        a, b = free[rng.integers(len(free), size=2)]
        if np.hypot(*(a - b)) >= 0.5 * span or len(free) < 100:
            out.append(((int(a[0]), int(a[1])), (int(b[0]), int(b[1]))))
    return out


def run(name: str, w: NDArray[np.float64], queries: list[tuple[tuple[int, int], tuple[int, int]]],
        backends: dict[str, Search], repeat: int) -> str:
    times: dict[str, list[float]] = {b: [] for b in backends}
    costs: dict[str, list[float]] = {b: [] for b in backends}
    for s, g in queries:
        for b, fn in backends.items():
            best = np.inf
            for _ in range(repeat):
                t0 = time.process_time()
                _, c = fn(w, s, g)
                best = min(best, time.process_time() - t0)
            times[b].append(best)
            costs[b].append(c)
    ours = np.asarray(costs["numba"])
    med = {b: float(np.median(times[b])) for b in backends}
    cells = [f"{1e3 * med[b]:8.2f}" for b in backends]
    if "pyastar2d" in med:
        ratio = med["numba"] / med["pyastar2d"]
        cells.append(f"{ratio:.2f}x ({'met' if ratio <= 1.5 else 'NOT met'})")
    checks = []
    if "mcp" in costs:
        err = float(np.max(np.abs(np.asarray(costs["mcp"]) - ours) / np.maximum(ours, 1e-9)))
        checks.append(f"MCP rel. diff {err:.1e} {'OK' if err < 1e-6 else 'MISMATCH'}")
    if "pyastar2d" in costs:
        excess = 100.0 * (np.asarray(costs["pyastar2d"]) / np.maximum(ours, 1e-9) - 1.0)
        checks.append(f"pyastar2d path +{float(np.mean(excess)):.2f}% (max +{float(np.max(excess)):.2f}%)")
    if "tcod" in costs:
        excess = 100.0 * (np.asarray(costs["tcod"]) / np.maximum(ours, 1e-9) - 1.0)
        checks.append(f"tcod path {float(np.mean(excess)):+.2f}% (max {float(np.max(excess)):+.2f}%)")
    return f"| {name:<22} | {w.shape[0]}x{w.shape[1]:<5} | {len(queries):3d} | " + " | ".join(cells) \
        + f" | {'; '.join(checks)} |"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="*", default=[0, 1, 2], help="apartment seeds")
    ap.add_argument("--queries", type=int, default=20, help="start/goal pairs per map")
    ap.add_argument("--seed", type=int, default=0, help="seed of the pairs and the random grid")
    ap.add_argument("--repeat", type=int, default=3, help="runs per query; the fastest counts")
    args = ap.parse_args()

    backends: dict[str, Search] = {}
    for name in ("numba", "pyastar2d", "tcod", "mcp"):
        try:
            backends[name] = BACKENDS.create(name)
        except Exception as e:  # a reference library missing: say so and go on
            print(f"# skipping {name}: {e}")
    warm = np.ones((8, 8))
    t0 = time.perf_counter()
    backends["numba"](warm, (0, 0), (7, 7))
    print(f"# numba A* first call (load or compile): {time.perf_counter() - t0:.2f} s, not counted below")
    cfg = PlannerConfig()
    flat = PlannerConfig(clearance_cost=0.0)
    print(f"# median over queries of the min CPU ms of {args.repeat} runs")
    print(f"# apartments: sim.obstacles(0.05) inflated by {cfg.inflation:.2f} m, with the "
          f"clearance cost (weights 1..{1 + cfg.clearance_cost:g}) and without it (uniform); pairs seed {args.seed}")
    ratio = ["numba / pyastar2d (target <= 1.5x)"] if "pyastar2d" in backends else []
    print("| map                    | cells     |   n | " + " | ".join([f"{b:>8}" for b in backends] + ratio)
          + " | costs |")
    print("|---|---|---:|" + "---:|" * (len(backends) + len(ratio)) + "---|")
    for seed in args.seeds:
        for tag, c in (("", cfg), (" uniform", flat)):
            w = apartment_weights(seed, c)
            print(run(f"apartment {seed}{tag}", w, pairs(w, args.queries, args.seed), backends, args.repeat),
                  flush=True)
    w = random_weights(args.seed)
    print(run("random 800x800, 25%", w, pairs(w, max(args.queries // 4, 3), args.seed), backends, args.repeat),
          flush=True)


if __name__ == "__main__":
    main()
