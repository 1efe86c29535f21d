"""A* time: CapNav's numba A* beside pyastar2d, libtcod and scikit-image's MCP_Geometric, in one run.

Maps: the inflated true obstacle maps of generated apartments (0.05 m cells) and 800x800 and
2000x2000 grids with random obstacles. Each backend solves the same seeded start/goal pairs on the
same weight grid (float32, as ``build_costmap`` makes it; each library gets it in its native form
before the clock starts), all 8-connected; a query's time is the smallest process CPU time of
``--repeat`` runs (the machine is shared), and the table gives the median over queries, our time
over pyastar2d's against the target (<= 1.2x on every row) and our expansions per second.
It checks the costs: MCP solves the same problem (step length times mean cell weight) and must
agree; pyastar2d prices a diagonal step like a straight one, so its paths are optimal only for
that metric, and we report how much longer they are under ours; libtcod (diagonal sqrt(2)) is the
reference with octile costs: on uniform grids its paths are optimal under ours too (it prices a
step by the cell entered, so on graded grids they are not).

    .venv/bin/python benchmarks/bench_astar.py [--seeds 0 1 2] [--queries 30] [--seed 0] [--repeat 3]
        [--random 800 2000]
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from capnav.planning import BACKENDS, PlannerConfig, build_costmap
from capnav.planning.search import expanded

TARGET = 1.2  # CapNav's A* time over pyastar2d's, on every row

Search = Callable[[NDArray[np.float64], tuple[int, int], tuple[int, int]], tuple[NDArray[np.intp], float]]


def apartment_weights(seed: int, cfg: PlannerConfig) -> NDArray[np.float32]:
    from capnav.sim import Simulator

    sim = Simulator.from_seed(seed)
    return build_costmap(sim.obstacles(resolution=0.05), cfg).weights


def random_weights(seed: int, size: int = 800, p_block: float = 0.25) -> NDArray[np.float32]:
    rng = np.random.default_rng(seed)
    w = np.ones((size, size), np.float32)
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


def run(name: str, w: NDArray[np.float32], queries: list[tuple[tuple[int, int], tuple[int, int]]],
        backends: dict[str, Search], repeat: int) -> tuple[str, bool | None]:
    rates: list[float] = []
    times: dict[str, list[float]] = {b: [] for b in backends}
    costs: dict[str, list[float]] = {b: [] for b in backends}
    grids = {b: (w.astype(np.float64) if b == "mcp" else w) for b in backends}  # MCP works in float64
    n_expanded = 0
    for s, g in queries:
        for b, fn in backends.items():
            best = np.inf
            for _ in range(repeat):
                t0 = time.process_time()
                _, c = fn(grids[b], s, g)
                best = min(best, time.process_time() - t0)
                if b == "numba":
                    n_expanded = expanded(grids[b])
            times[b].append(best)
            costs[b].append(c)
            if b == "numba":
                rates.append(n_expanded / max(best, 1e-9))
    ours = np.asarray(costs["numba"])
    med = {b: float(np.median(times[b])) for b in backends}
    cells = [f"{1e3 * med[b]:8.2f}" for b in backends]
    met = None
    if "pyastar2d" in med:
        ratio = med["numba"] / med["pyastar2d"]
        met = ratio <= TARGET
        cells.append(f"{ratio:.2f}x ({'met' if met else 'NOT met'})")
    cells.append(f"{np.median(rates) / 1e6:.1f}")
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
        + f" | {'; '.join(checks)} |", met


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="*", default=[0, 1, 2], help="apartment seeds")
    ap.add_argument("--queries", type=int, default=30, help="start/goal pairs per map (at least 30)")
    ap.add_argument("--random", type=int, nargs="*", default=[800, 2000], help="sizes of the random grids")
    ap.add_argument("--seed", type=int, default=0, help="seed of the pairs and the random grid")
    ap.add_argument("--repeat", type=int, default=3, help="runs per query; the fastest counts")
    args = ap.parse_args()
    if args.queries < 30:
        ap.error("--queries must be at least 30: medians over fewer pairs hide the slow rows")

    backends: dict[str, Search] = {}
    for name in ("numba", "pyastar2d", "tcod", "mcp"):
        try:
            backends[name] = BACKENDS.create(name)
        except Exception as e:  # a reference library missing: say so and go on
            print(f"# skipping {name}: {e}")
    warm = np.ones((8, 8), np.float32)
    t0 = time.perf_counter()
    backends["numba"](warm, (0, 0), (7, 7))
    print(f"# numba A* first call (load or compile): {time.perf_counter() - t0:.2f} s, not counted below")
    cfg = PlannerConfig()
    flat = PlannerConfig(clearance_cost=0.0)
    print(f"# median over queries of the min CPU ms of {args.repeat} runs")
    print(f"# apartments: sim.obstacles(0.05) inflated by {cfg.inflation:.2f} m, with the "
          f"clearance cost (weights 1..{1 + cfg.clearance_cost:g}) and without it (uniform); pairs seed {args.seed}")
    ratio = [f"numba / pyastar2d (target <= {TARGET}x)"] if "pyastar2d" in backends else []
    ratio.append("numba M expansions/s")
    print("| map                    | cells     |   n | " + " | ".join([f"{b:>8}" for b in backends] + ratio)
          + " | costs |")
    print("|---|---|---:|" + "---:|" * (len(backends) + len(ratio)) + "---|")
    verdicts: list[bool | None] = []
    rows: list[tuple[str, NDArray[np.float32]]] = []
    for seed in args.seeds:
        for tag, c in (("", cfg), (" uniform", flat)):
            rows.append((f"apartment {seed}{tag}", apartment_weights(seed, c)))
    for size in args.random:
        rows.append((f"random {size}x{size}, 25%", random_weights(args.seed, size)))
    for name, w in rows:
        line, met = run(name, w, pairs(w, args.queries, args.seed), backends, args.repeat)
        verdicts.append(met)
        print(line, flush=True)
    if all(v is not None for v in verdicts):
        n_met = sum(bool(v) for v in verdicts)
        print(f"# target numba <= {TARGET}x pyastar2d: met on {n_met} of {len(verdicts)} rows"
              f"{'' if n_met == len(verdicts) else ' (NOT met on every row)'}; load average "
              f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs")


if __name__ == "__main__":
    main()
