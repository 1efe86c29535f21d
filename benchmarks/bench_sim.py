"""Simulator speed: frames/s of ``Simulator.render`` at 320x240 and 640x480 and the scene build time,
beside a reference: raw pybullet ``getCameraImage`` (tiny renderer) on the same scene and poses,
without our room culling or post-processing (depth linearisation, truth images).

Both wall-clock and CPU-time rates are printed: on a shared machine the CPU-time rate is what one
free core would give. Poses are the first frames of each apartment's exploration pass.

    .venv/bin/python benchmarks/bench_sim.py [--seeds 0 1 2] [--frames 100]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

import numpy as np

from capnav.sim import ExploreConfig, Simulator
from capnav.sim.camera import projection_matrix, view_matrix
from capnav.sim.explore import plan_exploration


def _rates(fn, n: int) -> tuple[float, float]:  # type: ignore[no-untyped-def]
    w, c = time.perf_counter(), time.process_time()
    fn()
    return n / (time.perf_counter() - w), n / (time.process_time() - c)


def _raw(world, K, P, poses) -> None:  # type: ignore[no-untyped-def]
    p = world.p
    for T in poses:
        p.getCameraImage(K.width, K.height, view_matrix(T), P, renderer=p.ER_TINY_RENDERER,
                         physicsClientId=world.client)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--frames", type=int, default=100)
    args = ap.parse_args()
    rows = []
    for seed in args.seeds:
        t0 = time.perf_counter()
        sim = Simulator.from_seed(seed)
        build = time.perf_counter() - t0
        poses = plan_exploration(sim, ExploreConfig(seed=seed, max_frames=args.frames))
        for w, h in ((320, 240), (640, 480)):
            K = replace(sim.config.camera, width=w, height=h).intrinsics()
            P = projection_matrix(K, sim.config.camera.near, sim.config.camera.far)
            ours = _rates(lambda K=K, sim=sim, poses=poses: [sim.render(T, K=K, index=i)
                                                             for i, T in enumerate(poses)], len(poses))
            sim.world.show_rooms(set(range(len(sim.apartment.plan.rooms))))  # reference: everything drawn
            ref = _rates(lambda K=K, P=P, world=sim.world, poses=poses: _raw(world, K, P, poses), len(poses))
            rows.append((seed, len(sim.manifest.rooms), len(sim.manifest.objects), build, f"{w}x{h}", ours, ref))
        sim.close()
    print(f"{'seed':>4} {'rooms':>5} {'objs':>4} {'build s':>7} {'size':>8} | {'ours fps (wall/cpu)':>20} | "
          f"{'raw pybullet fps (wall/cpu)':>28}")
    for seed, nr, no, build, size, ours, ref in rows:
        print(f"{seed:>4} {nr:>5} {no:>4} {build:>7.2f} {size:>8} | {ours[0]:>9.1f} / {ours[1]:>8.1f} | "
              f"{ref[0]:>13.1f} / {ref[1]:>12.1f}")
    for size in ("320x240", "640x480"):
        o = [r[5][1] for r in rows if r[4] == size]
        f = [r[6][1] for r in rows if r[4] == size]
        print(f"mean CPU-time fps at {size}: ours {np.mean(o):.1f}, raw pybullet {np.mean(f):.1f}")
    print(f"mean scene build time: {np.mean([r[3] for r in rows]):.2f} s (primitives, SimConfig defaults)")


if __name__ == "__main__":
    main()
