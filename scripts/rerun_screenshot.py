"""Picture of a map's 3D view for the README: ``capnav view MAP -q INSTRUCTION`` writes the .rrd,
rerun's own viewer (headless, software Vulkan when there is no GPU) opens it with the layout
stored in it, and the screenshot is saved as a small palette PNG.

    .venv/bin/python scripts/rerun_screenshot.py MAP -q "the pink armchair" -o docs/view/rerun.png \\
        [--robot X,Y] [--max-z 2.0] [--size 1280,800] [--settle 12]
"""

from __future__ import annotations

import argparse
import io
import subprocess
import sys
import tempfile
from pathlib import Path

from PIL import Image

from capnav.core.atomic import write_bytes
from capnav.viz.rerun_shot import screenshot_rrd


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("map", type=Path)
    ap.add_argument("-q", "--query", action="append", default=[], help="an instruction to answer (repeatable)")
    ap.add_argument("-o", "--out", type=Path, default=Path("docs/view/rerun.png"))
    ap.add_argument("--robot", help="X,Y in metres (default: the map's last camera pose)")
    ap.add_argument("--max-z", default="2.0", help="leave out voxels above this height (m): the ceiling")
    ap.add_argument("--size", default="1280,800", help="viewer W,H in points")
    ap.add_argument("--settle", type=float, default=12.0, help="seconds for the viewer's start-up notices to fade")
    ap.add_argument("--colours", type=int, default=256, help="palette size of the PNG (0: full colour)")
    args = ap.parse_args()
    w, h = (int(v) for v in args.size.split(","))
    with tempfile.TemporaryDirectory(prefix="capnav-rrd-") as tmp:
        rrd = Path(tmp) / "map.rrd"
        cmd = [sys.executable, "-m", "capnav.cli", "view", str(args.map), "-o", str(rrd), "--max-z", args.max_z]
        for q in args.query:
            cmd += ["-q", q]
        if args.robot:
            cmd += ["--robot", args.robot]
        subprocess.run(cmd, check=True)
        shot = screenshot_rrd(rrd, size=(w, h), settle=args.settle)
    img = Image.open(io.BytesIO(shot.png)).convert("RGB")
    if args.colours:
        img = img.quantize(colors=args.colours, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
    buf = io.BytesIO()
    img.save(buf, format="PNG", optimize=True)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    write_bytes(args.out, buf.getvalue())
    views = ", ".join(f"{n} ({k})" for n, k in shot.views)
    print(f"{args.out}: {img.width}x{img.height}, {len(buf.getvalue()) / 1024:.0f} KB; frame {shot.frame}; "
          f"views {views}")


if __name__ == "__main__":
    main()
