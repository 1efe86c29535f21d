"""What the benchmark scripts share: the repository root, the folders of the shared detector
weights, and the plain-text table every script prints (a title, aligned columns)."""

from __future__ import annotations

import argparse
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
#: Detector name -> folder under ../shared/weights (or a `capnav models` install).
WEIGHT_FOLDERS = {"yolo-fastest": "yolo-fastest-1.1-xl", "centernet": "centernet-mobilenetv3-coco"}


def table(title: str, header: list[str], rows: list[list[str]]) -> None:
    """Print ``rows`` under ``header`` with columns padded to their widest cell."""
    widths = [max(len(str(r[i])) for r in [header, *rows]) for i in range(len(header))]
    print(f"\n## {title}")
    print("  ".join(h.ljust(w) for h, w in zip(header, widths, strict=True)))
    print("  ".join("-" * w for w in widths))
    for r in rows:
        print("  ".join(str(c).ljust(w) for c, w in zip(r, widths, strict=True)))


def add_sh3d_args(ap: argparse.ArgumentParser) -> None:
    """The options of scripts that render Sweet Home 3D apartments once and cache them."""
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=480)
    ap.add_argument("--cache", type=Path, default=Path("data/bench"))
    ap.add_argument("--assets-dir", type=Path, default=None)
