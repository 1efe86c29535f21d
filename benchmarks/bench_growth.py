"""Growth with house size: mapping CPU time, peak memory and map size for houses of 1..k tiled
apartments, as a table and a PNG plot.

    .venv/bin/python benchmarks/bench_growth.py [--tiles 1 2 3] [--frame-step 2] [--plot growth.png]

A house of k tiles is apartments 0..k-1 (simulator seeds, each explored with seed 0), apartment i
shifted by (12 i, 12 i) m: along a diagonal, so the observed surface grows like k while the
bounding box grows like k^2, and the table says which one each resource follows. Every
``--frame-step``-th frame is mapped (default detector noise, detector seed 0, one thread). Mapping
time is process CPU time; peak memory is the tracemalloc peak of Python / numpy allocations while
mapping (rendering excluded: frames are rendered first); the map is written with the default
format (float16 features, deflate).
"""

from __future__ import annotations

import os

for _v in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
import tracemalloc  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

SHIFT = 12.0  # m between tiles, along x and y


def tiled_frames(k: int, step: int) -> list:
    from bench_mapping import render

    out: list = []
    for i in range(k):
        sim, frames = render(i)
        sim.close()  # type: ignore[attr-defined]
        for f in frames[::step]:
            T = f.T_wc.copy()
            T[:2, 3] += SHIFT * i
            out.append(dataclasses.replace(f, index=len(out), T_wc=T))
    return out


def measure(k: int, step: int) -> dict[str, float]:
    from capnav.io.mapfile import save_map
    from capnav.language import create_embedder
    from capnav.mapping import Mapper, MapperConfig
    from capnav.perception import create_detector, create_encoder

    frames = tiled_frames(k, step)
    m = Mapper(MapperConfig(), create_detector("sim", noise="default", seed=0),
               create_encoder("label-embedding", embedder=create_embedder("minilm", threads=1)))
    m.integrate(frames[0])  # compile / cache load and the vocabulary's embeddings, not counted
    m = Mapper(MapperConfig(), m.detector, m.encoder)
    tracemalloc.start()
    t0 = time.process_time()
    for f in frames:
        m.integrate(f)
    cmap = m.finish()
    cpu = time.process_time() - t0
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    with tempfile.TemporaryDirectory() as d:
        size = save_map(cmap, Path(d) / "m.capnav").stat().st_size
    c = cmap.voxels.centers()
    bbox = float(np.prod(c[:, :2].max(0) - c[:, :2].min(0)))
    return {"tiles": k, "frames": len(frames), "voxels": len(cmap.voxels), "objects": len(cmap.objects),
            "bbox_m2": bbox, "occ_cells": cmap.occupancy.cells.size, "cpu_s": cpu, "peak_mib": peak / 2**20,
            "file_mib": size / 2**20}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tiles", type=int, nargs="+", default=[1, 2, 3])
    ap.add_argument("--frame-step", type=int, default=2)
    ap.add_argument("--plot", type=Path, default=Path("growth.png"))
    args = ap.parse_args()
    rows = []
    for k in args.tiles:
        rows.append(measure(k, args.frame_step))
        print(f"# {k} tile(s) done", flush=True)
    base = rows[0]
    keys = [("frames", "frames", "{:.0f}"), ("voxels", "voxels", "{:,.0f}"), ("bbox_m2", "bbox m^2", "{:.0f}"),
            ("occ_cells", "occupancy cells", "{:,.0f}"), ("cpu_s", "mapping CPU s", "{:.1f}"),
            ("peak_mib", "peak MiB", "{:.1f}"), ("file_mib", "file MiB", "{:.1f}")]
    print(f"\n## growth with house size (apartments 0..k-1 on a diagonal, every {args.frame_step}-th frame; "
          f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)")
    print("| tiles | " + " | ".join(h for _, h, _ in keys) + " |")
    print("|---:|" + "---:|" * len(keys))
    for r in rows:
        print(f"| {r['tiles']} | " + " | ".join(fmt.format(r[k]) for k, _, fmt in keys) + " |")
    if len(rows) > 1:
        x = np.log([r["tiles"] for r in rows])
        print("\ngrowth exponent b in value ~ tiles^b (least squares on log-log; 1 = with observed surface, "
              "2 = with the bounding box):")
        for k, h, _ in keys:
            y = np.log([max(r[k], 1e-9) for r in rows])
            print(f"- {h}: b = {np.polyfit(x, y, 1)[0]:.2f}")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    t = [r["tiles"] for r in rows]
    for k, h, _ in keys[1:]:
        ax.plot(t, [r[k] / base[k] for r in rows], marker="o", label=h)
    ax.plot(t, t, "k--", lw=0.8, label="linear (surface)")
    ax.plot(t, [v * v for v in t], "k:", lw=0.8, label="quadratic (bounding box)")
    ax.set_xlabel("apartments in the house (tiles)")
    ax.set_ylabel("relative to one apartment")
    ax.set_xticks(t)
    ax.legend(fontsize=8)
    ax.set_title("CapNav mapping: growth with house size")
    fig.tight_layout()
    fig.savefig(args.plot, dpi=100)
    print(f"\nplot: {args.plot}")


if __name__ == "__main__":
    main()
