"""Does the agent get within 1 m of every reachable instance? Truth vs mapped occupancy.

For each generated apartment and each object instance the agent can reach (a navigable cell lies
within 1 m of its footprint), the agent is spawned at seeded random navigable starts and
``navigate_to`` drives it to the instance's true footprint on either the true obstacle map
(``sim.obstacles``) or the occupancy CapNav mapped from the exploration pass (simulator detector,
default noise). Success is the evaluation's rule: the stop point within 1 m of the true footprint.
Retrieval is not involved: this measures goal selection, A* and execution only.

    .venv/bin/python benchmarks/eval_reach.py [--seeds 0 1 2] [--starts 3] [--seed 0]
        [--occupancy truth mapped] [--map-cache DIR]

Targets: >= 99% with the true occupancy, >= 95% with the mapped one.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from capnav.core.footprint import footprint_distance
from capnav.core.grid import FREE, OccupancyGrid
from capnav.planning import PlannerConfig, build_costmap, navigate_to
from capnav.sim.success import SUCCESS_RADIUS_M

TARGET = {"truth": 0.99, "mapped": 0.95}


def mapped_occupancy(sim: Any, seed: int, cache: Path | None, max_frames: int | None, noisy: bool) -> OccupancyGrid:
    """Explore, map (CapNav's mapping stage) and return the map's occupancy; cached per setting."""
    from capnav.io.mapfile import load_map, save_map
    from capnav.mapping import build_map
    from capnav.sim import ExploreConfig, explore

    tag = f"{'' if max_frames is None else f'_f{max_frames}'}{'_noisy' if noisy else ''}"
    path = None if cache is None else cache / f"apartment_{seed}{tag}.capnav"
    if path is not None and path.exists():
        return load_map(path).occupancy
    frames = explore(sim, ExploreConfig(max_frames=max_frames))
    cmap = build_map(frames, progress=False, meta={"scene_seed": seed})
    if path is not None:
        save_map(cmap, path)
    return cmap.occupancy


def reachable(nav: OccupancyGrid, footprint: np.ndarray) -> bool:
    pts = nav.spec.to_world(np.argwhere(nav.cells == FREE))
    return bool(footprint_distance(pts, footprint).min() <= SUCCESS_RADIUS_M)


def run(sim: Any, occ: OccupancyGrid, starts: int, seed: int, cfg: PlannerConfig) -> dict[str, Any]:
    nav = sim.navigable()
    cm = build_costmap(occ, cfg)
    rng = np.random.default_rng([sim.seed, seed])
    trials = ok = replans = collisions = 0
    unreachable: list[int] = []
    failures: list[str] = []
    t_nav = 0.0
    for inst in sim.manifest.objects:
        fp = np.asarray(inst.footprint, dtype=np.float64)
        if not reachable(nav, fp):
            unreachable.append(inst.id)
            continue
        for _ in range(starts):
            x, y = sim.random_navigable_point(rng)
            agent = sim.spawn_agent(x, y, float(rng.uniform(-np.pi, np.pi)))
            t0 = time.perf_counter()
            try:
                res = navigate_to(agent, occ, fp, cfg, cm)
                why, n_replans = res.reason, res.replans
            except Exception as e:  # bad start on the mapped grid etc.: a failure with its reason
                why, n_replans = f"{type(e).__name__}: {e}", 0
            t_nav += time.perf_counter() - t0
            d = float(footprint_distance(np.asarray(agent.pose[:2]).reshape(1, 2), fp)[0])
            trials += 1
            replans += n_replans
            collisions += agent.collisions
            if d <= SUCCESS_RADIUS_M:
                ok += 1
            else:
                failures.append(f"#{inst.id} {inst.category} from ({x:.2f}, {y:.2f}): {d:.2f} m; {why}")
    return {"instances": len(sim.manifest.objects), "reachable": len(sim.manifest.objects) - len(unreachable),
            "trials": trials, "ok": ok, "replans": replans, "collisions": collisions,
            "ms": 1e3 * t_nav / max(trials, 1), "failures": failures}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="*", default=[0, 1, 2], help="apartment seeds")
    ap.add_argument("--starts", type=int, default=3, help="random starts per instance")
    ap.add_argument("--seed", type=int, default=0, help="seed of the starts")
    ap.add_argument("--occupancy", nargs="*", default=["truth", "mapped"], choices=["truth", "mapped"])
    ap.add_argument("--map-cache", type=Path, default=None, help="folder to keep the mapped apartments in")
    ap.add_argument("--max-frames", type=int, default=None, help="map from at most this many exploration frames")
    ap.add_argument("--depth-noise", action="store_true", help="Kinect-like depth noise in the mapped frames")
    ap.add_argument("--unknown-cost", default=None, help="planner weight of unknown cells, or 'blocked'")
    args = ap.parse_args()
    from capnav.sim import DepthNoiseConfig, SimConfig, Simulator

    cfg = PlannerConfig()
    if args.unknown_cost is not None:
        cfg = replace(cfg, unknown_cost=None if args.unknown_cost == "blocked" else float(args.unknown_cost))
    if args.map_cache is not None:
        args.map_cache.mkdir(parents=True, exist_ok=True)
    print(f"# {cfg}")
    print(f"# starts per instance {args.starts}, start seed {args.seed}; success = stop within "
          f"{SUCCESS_RADIUS_M} m of the true footprint; mapping: max_frames={args.max_frames}, "
          f"depth noise {'on' if args.depth_noise else 'off'}")
    rows, totals = [], {k: [0, 0] for k in args.occupancy}
    for seed in args.seeds:
        sim = Simulator.from_seed(seed, SimConfig(depth_noise=DepthNoiseConfig(enabled=args.depth_noise, seed=seed)))
        for kind in args.occupancy:
            occ = sim.obstacles() if kind == "truth" else mapped_occupancy(sim, seed, args.map_cache, args.max_frames,
                                                                             args.depth_noise)
            r = run(sim, occ, args.starts, args.seed, cfg)
            totals[kind][0] += r["ok"]
            totals[kind][1] += r["trials"]
            rows.append(f"| {seed} | {kind} | {r['reachable']}/{r['instances']} | {r['trials']} | "
                        f"{100.0 * r['ok'] / max(r['trials'], 1):.1f} | {r['replans']} | {r['collisions']} | "
                        f"{r['ms']:.1f} |")
            print(rows[-1], flush=True)
            for f in r["failures"]:
                print(f"#   fail: {f}")
        sim.close()
    print()
    print("| seed | occupancy | reachable / instances | trials | success % | replans | contacts* | ms / nav |")
    print("|---:|---|---:|---:|---:|---:|---:|---:|")
    print("\n".join(rows))
    for kind, (ok, n) in totals.items():
        rate = ok / max(n, 1)
        print(f"| all | {kind} | | {n} | {100.0 * rate:.1f} (target {100 * TARGET[kind]:.0f}"
              f"{', met' if rate >= TARGET[kind] else ', NOT met'}) | | | |")
    print("(*) agent contacts, including the bumper probes after each collision")


if __name__ == "__main__":
    main()
