"""Mapping benchmark: throughput, voxel fusion vs Open3D, peak memory, and map quality.

    .venv/bin/python benchmarks/bench_mapping.py [--seeds 0 1 2] [--noise default] [--no-quality]

1. Mapping throughput in frames/s at the simulator's 320x240, rendering excluded (frames are
   rendered first), per stage, on one core (numba / BLAS / onnxruntime limited to one thread).
2. Voxel fusion in points/s on the same back-projected points: CapNav's eq. 5-8 fusion (64-dim
   features + colour + weight, incremental) side by side with Open3D's ``voxel_down_sample``
   (colour + position only, one batch call), min CPU time of 3 runs each, with the ratio beside
   the project's targets. Open3D's voxels differ in number: it puts the grid origin at the cloud's
   minimum corner, ours at eq. 4's fixed origin. Skipped with a message if open3d is not installed.
3. Peak memory while mapping a whole apartment (tracemalloc peak of Python/numpy allocations, and
   the process's max RSS), and the size of the map.
4. Mapping quality on each seed's apartment at the given detector noise vs the project's mapping targets.
"""

from __future__ import annotations

import os

for _v in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import resource  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
import tracemalloc  # noqa: E402
from collections.abc import Callable  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from numpy.typing import NDArray  # noqa: E402

from bench_common import table  # noqa: E402

DEPTH_NOISE = False  # set by --depth-noise


def render(seed: int) -> tuple[object, list]:
    from capnav.sim.config import DepthNoiseConfig, SimConfig
    from capnav.sim.explore import ExploreConfig, explore
    from capnav.sim.simulator import Simulator

    sim = Simulator.from_seed(seed, SimConfig(depth_noise=DepthNoiseConfig(enabled=DEPTH_NOISE)))
    return sim, list(explore(sim, ExploreConfig(seed=0)))


class _Timed:
    """Wrap a detector / encoder to accumulate its CPU time (this thread only, so other processes
    on a shared machine do not inflate it)."""

    def __init__(self, inner: object, method: str) -> None:
        self.inner, self.method, self.seconds = inner, method, 0.0
        for k in ("id", "dim", "text_space"):
            if hasattr(inner, k):
                setattr(self, k, getattr(inner, k))

    def __getattr__(self, name: str) -> object:
        fn = getattr(self.inner, name)
        if name != self.method:
            return fn

        def timed(*a: object, **kw: object) -> object:
            t0 = time.thread_time()
            try:
                return fn(*a, **kw)
            finally:
                self.seconds += time.thread_time() - t0

        return timed


def throughput(frames: list, noise: str) -> tuple[list[list[str]], object]:
    from capnav.language import create_embedder
    from capnav.mapping import Mapper, MapperConfig
    from capnav.perception import create_detector, create_encoder

    emb = create_embedder("minilm")
    det = _Timed(create_detector("sim", noise=noise, seed=0), "detect")
    enc = _Timed(create_encoder("label-embedding", embedder=emb), "encode_indexed")
    warm = Mapper(MapperConfig(), det, enc)  # type: ignore[arg-type]
    warm.integrate(frames[0])  # numba compile / cache load and the vocabulary's embeddings
    det.seconds = enc.seconds = 0.0
    m = Mapper(MapperConfig(), det, enc)  # type: ignore[arg-type]
    fuse = 0.0
    orig = m.voxels.integrate_frame

    def timed_fuse(*a: object, **kw: object) -> None:
        nonlocal fuse
        t0 = time.thread_time()
        orig(*a, **kw)  # type: ignore[arg-type]
        fuse += time.thread_time() - t0

    m.voxels.integrate_frame = timed_fuse  # type: ignore[method-assign]
    w0, t0 = time.perf_counter(), time.thread_time()
    for f in frames:
        m.integrate(f)
    total, wall = time.thread_time() - t0, time.perf_counter() - w0
    t1 = time.thread_time()
    cmap = m.finish()
    fin = time.thread_time() - t1
    n = len(frames)
    rest = total - det.seconds - enc.seconds - fuse
    rows = [
        ["detector (sim, noise model)", f"{1000 * det.seconds / n:.2f}", ""],
        ["dense encoder (label embedding)", f"{1000 * enc.seconds / n:.2f}", ""],
        ["voxel fusion eq. 2-8", f"{1000 * fuse / n:.2f}", ""],
        ["lifting + SG3DTracker + memory", f"{1000 * rest / n:.2f}", ""],
        ["per frame, all stages (CPU time)", f"{1000 * total / n:.2f}", f"{n / total:.1f} frames/s (target >= 30)"],
        ["per frame, all stages (wall clock)", f"{1000 * wall / n:.2f}", f"{n / wall:.1f} frames/s "
         f"(load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)"],
        ["finish (merge, export, occupancy)", f"{1000 * fin:.0f} (once)", ""],
    ]
    return rows, cmap


def detector_stats(frames: list) -> list[list[str]]:
    """Per-frame behaviour of the simulator detector against the truth images, per noise level."""
    from capnav.core.categories import BY_ID
    from capnav.perception import NOISE_PRESETS, create_detector

    rows = []
    for noise in NOISE_PRESETS:
        det = create_detector("sim", noise=noise, seed=0)
        vis = hit = big_vis = big_hit = swapped = fp = n = 0
        scores = []
        for f in frames:
            ids, cnt = np.unique(f.gt_instance, return_counts=True)
            seen = {int(i): int(c) for i, c in zip(ids, cnt, strict=True) if i > 0 and c >= 100}
            vis += len(seen)
            big_vis += sum(c >= 2000 for c in seen.values())
            for d in det.detect(f):
                n += 1
                scores.append(d.score)
                under = f.gt_instance[d.mask]
                inst = int(np.bincount(under).argmax())
                if inst == 0 or (under == inst).mean() < 0.5:
                    fp += 1
                    continue
                truth = BY_ID[int(np.bincount(f.gt_category[f.gt_instance == inst]).argmax())].name
                hit += inst in seen
                big_hit += seen.get(inst, 0) >= 2000
                swapped += d.label != truth
        rows.append([noise, f"{hit / max(vis, 1):.0%}", f"{big_hit / max(big_vis, 1):.0%}",
                     f"{swapped / max(n - fp, 1):.1%}", f"{fp / len(frames):.3f}", f"{np.mean(scores):.2f}"])
    return rows


def _best_cpu(fn: Callable[[], object], repeat: int) -> tuple[float, object]:
    """Smallest process CPU time of ``repeat`` calls (all threads; the min is the least disturbed
    by the other jobs of a shared machine) and the last result."""
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.process_time()
        out = fn()
        best = min(best, time.process_time() - t0)
    return best, out


def fusion_vs_open3d(frames: list, repeat: int = 3) -> list[list[str]]:
    """Both on the same back-projected points of every frame, 5 cm voxels, one thread, min CPU
    time of ``repeat`` runs. Targets: colour at >= 1x Open3D's rate, 64-d >= 0.5x."""
    from capnav.core.geometry import backproject
    from capnav.mapping import VoxelConfig, VoxelMap

    pts, cols = [], []
    for f in frames:
        pc, flat = backproject(f.depth, f.K, f.T_wc)
        pts.append(pc)
        cols.append(f.rgb.reshape(-1, 3)[flat])
    p = np.concatenate(pts).astype(np.float64)
    c = np.concatenate(cols)
    n = len(p)
    alpha = np.ones(n, np.float32)
    phi = np.random.default_rng(0).standard_normal((64, 64)).astype(np.float32)
    fidx = np.random.default_rng(1).integers(0, 64, n)
    origin = VoxelConfig().grid_origin
    ours: dict[int, tuple[float, int]] = {}
    for dim in (64, 1):
        feats = np.ascontiguousarray(phi[:, :dim])
        VoxelMap(0.05, origin, feature_dim=dim).integrate(p[:1000], alpha[:1000], c[:1000], fidx[:1000], feats)

        def fuse(dim: int = dim, feats: NDArray[np.float32] = feats) -> VoxelMap:
            vm = VoxelMap(0.05, origin, feature_dim=dim)
            vm.integrate(p, alpha, c, fidx, feats)
            return vm

        dt, vm = _best_cpu(fuse, repeat)
        ours[dim] = (dt, len(vm))  # type: ignore[arg-type]
    try:
        import open3d as o3d
    except ImportError:
        return [[f"CapNav eq. 5-8 fusion, {d}-d feature + colour + weight", f"{n:,}", f"{v:,}",
                 f"{n / t / 1e6:.1f} M/s", "skipped: open3d not installed (.venv/bin/pip install open3d)"]
                for d, (t, v) in ours.items()]
    pcd = o3d.geometry.PointCloud()
    pcd.points = o3d.utility.Vector3dVector(p)
    pcd.colors = o3d.utility.Vector3dVector(c.astype(np.float64) / 255.0)
    pcd.voxel_down_sample(0.05)
    dt3, ds = _best_cpu(lambda: pcd.voxel_down_sample(0.05), repeat)
    rows = []
    for dim, target in ((64, 0.5), (1, 1.0)):
        t, v = ours[dim]
        ratio = dt3 / t
        rows.append([f"CapNav eq. 5-8 fusion, {dim}-d feature + colour + weight", f"{n:,}", f"{v:,}",
                     f"{n / t / 1e6:.1f} M/s", f"{ratio:.2f}x Open3D (target >= {target:g}x: "
                     f"{'met' if ratio >= target else 'NOT met'})"])
    rows.append([f"Open3D {o3d.__version__} voxel_down_sample (colour, one batch call)", f"{n:,}",
                 f"{len(ds.points):,}", f"{n / dt3 / 1e6:.1f} M/s", "reference"])  # type: ignore[attr-defined]
    return rows


def memory(seed: int, noise: str) -> list[list[str]]:
    """Run in a fresh process: stream the apartment from the simulator through the mapper."""
    import json
    import subprocess
    import sys

    out = subprocess.run([sys.executable, __file__, "--memory-probe", str(seed), "--noise", noise],
                         capture_output=True, text=True, check=True)
    r = json.loads(out.stdout.strip().splitlines()[-1])
    return [
        ["process peak RSS: simulator + renderer + mapper, frames streamed", f"{r['rss'] / 1024:.0f} MiB"],
        ["... of which before mapping (simulator, MiniLM, imports)", f"{r['rss0'] / 1024:.0f} MiB"],
        ["peak traced Python/numpy allocations while mapping", f"{r['peak'] / 2**20:.1f} MiB"],
        [f"voxel map ({r['voxels']:,} voxels, {r['dim']}-d float32 features)", f"{r['vox_bytes'] / 2**20:.1f} MiB"],
        [f"objects ({r['objects']}, bounded point samples)", f"{r['obj_bytes'] / 2**20:.2f} MiB"],
        ["map file on disk", f"{r['file'] / 2**20:.1f} MiB"],
    ]


def _hwm_kib() -> int:
    """Peak resident set of this process (VmHWM; unlike ru_maxrss it is not inherited over exec)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1])
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


def _memory_probe(seed: int, noise: str) -> None:
    import json

    from capnav.io.mapfile import save_map
    from capnav.language import create_embedder
    from capnav.mapping import Mapper, MapperConfig
    from capnav.perception import create_detector, create_encoder
    from capnav.sim.explore import ExploreConfig, explore
    from capnav.sim.simulator import Simulator

    sim = Simulator.from_seed(seed)
    enc = create_encoder("label-embedding", embedder=create_embedder("minilm"))
    m = Mapper(MapperConfig(), create_detector("sim", noise=noise, seed=0), enc)
    rss0 = _hwm_kib()
    tracemalloc.start()
    for f in explore(sim, ExploreConfig(seed=0)):
        m.integrate(f)
    cmap = m.finish()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    vox = cmap.voxels
    with tempfile.TemporaryDirectory() as d:
        size = save_map(cmap, Path(d) / "m.capnav").stat().st_size
    print(json.dumps({
        "rss": _hwm_kib(), "rss0": rss0, "peak": peak, "voxels": len(vox),
        "dim": vox.dim, "vox_bytes": vox.features.nbytes + vox.colors.nbytes + vox.weights.nbytes + vox.keys.nbytes,
        "objects": len(cmap.objects), "file": size,
        "obj_bytes": sum(o.points.nbytes + o.colors.nbytes + o.feature.nbytes for o in cmap.objects)}))


def quality(seeds: list[int], noise: str) -> list[list[str]]:
    from capnav.eval.map_quality import evaluate_map, visible_frames
    from capnav.language import create_embedder
    from capnav.mapping import build_map
    from capnav.perception import create_detector, create_encoder

    emb = create_embedder("minilm")
    cols: list[list[tuple[str, str, str]]] = []
    for s in seeds:
        sim, frames = render(s)
        cmap = build_map(frames, detector=create_detector("sim", noise=noise, seed=0),
                         encoder=create_encoder("label-embedding", embedder=emb), progress=False)
        q = evaluate_map(cmap, sim.manifest, visible_frames(frames), sim.obstacles())  # type: ignore[attr-defined]
        cols.append(q.rows())
        sim.close()  # type: ignore[attr-defined]
    rows = []
    for k, (name, _, target) in enumerate(cols[0]):
        rows.append([name, *[c[k][1] for c in cols], target])
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--noise", default="default")
    ap.add_argument("--no-quality", action="store_true")
    ap.add_argument("--quality-only", action="store_true")
    ap.add_argument("--depth-noise", action="store_true", help="the simulator's Kinect-like depth noise")
    ap.add_argument("--memory-probe", type=int, default=None, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.memory_probe is not None:
        _memory_probe(args.memory_probe, args.noise)
        return
    global DEPTH_NOISE
    DEPTH_NOISE = args.depth_noise
    if args.quality_only:
        table(f"mapping quality, noise {args.noise!r}, detector seed 0, depth noise {args.depth_noise}",
               ["metric", *[f"seed {s}" for s in args.seeds], "target"], quality(args.seeds, args.noise))
        return
    sim, frames = render(args.seeds[0])
    h, w = frames[0].shape
    print(f"apartment seed {args.seeds[0]}: {len(frames)} frames at {w}x{h}, detector noise {args.noise!r}, "
          "detector seed 0, one thread")
    rows, _ = throughput(frames, args.noise)
    table("mapping throughput (rendering excluded)", ["stage", "ms / frame", "rate"], rows)
    table("simulator detector per frame (instances with >= 100 / >= 2000 visible px)",
           ["noise", "recall >=100px", "recall >=2000px", "label swapped", "false pos./frame", "mean score"],
           detector_stats(frames))
    table("voxel fusion on the same points (5 cm voxels; min CPU time of 3 runs)",
           ["method", "points", "voxels", "points/s", "ratio"],
           fusion_vs_open3d(frames))
    table(f"memory for a whole apartment (seed {args.seeds[0]})", ["what", "size"], memory(args.seeds[0], args.noise))
    sim.close()  # type: ignore[attr-defined]
    if not args.no_quality:
        table(f"mapping quality, noise {args.noise!r}, detector seed 0, depth noise {args.depth_noise}",
               ["metric", *[f"seed {s}" for s in args.seeds], "target"], quality(args.seeds, args.noise))


if __name__ == "__main__":
    main()
