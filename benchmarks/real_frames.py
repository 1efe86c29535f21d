"""The three real single RGB-D frames of ``../shared/realdata`` (TUM, NYU, SUN; read there at run
time, never copied into the project) as one-frame TUM recordings, run through the whole CLI as a
user would (``import auto`` without ``--up``, ``map --detector``, ``caption``, ``objects``,
``query --json``, ``navigate``), with requests written by looking at each colour image
(``REQUESTS``: what the request should answer, a COCO label or None for "not found").

    python benchmarks/real_frames.py --out runs/realframes [--detectors yolo-fastest centernet]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

SHARED = Path(__file__).resolve().parents[1].parent / "shared" / "realdata"
FILES = {"tum": ("TUM_color.png", "TUM_depth.png"), "nyu": ("NYU_color.ppm", "NYU_depth.pgm"),
         "sun": ("SUN_color.jpg", "SUN_depth.png")}

# (request, expected label or None = not found, expected reason word for None: "class" = the
# detector has no such class, "none" = there is none). Written from looking at the colour images.
REQUESTS: dict[str, list[tuple[str, str | None, str]]] = {
    # TUM: a desk of two tables in a row; a red office chair on the left, a yellow chair on the
    # right; bottles on the desk and on the shelf, a cup, scissors, a magazine, a toy plane.
    "tum": [
        ("the chair", "chair", ""),
        ("the yellow chair", "chair", ""),
        ("the red office chair", "chair", ""),
        ("the seat", "chair", ""),
        ("the bottle on the table", "bottle", ""),
        ("the bottle", "bottle", ""),
        ("the desk", "table", ""),
        ("the cup", "cup", ""),
        ("the sofa", None, "none"),
        ("the toilet", None, "none"),
        ("the cabinet", None, "class"),
        ("the lamp", None, "class"),
        ("the monitor", None, "none"),  # a detector class (tv), none on this desk
    ],
    # NYU: a basement; a white wardrobe (cabinet), plastic storage boxes, a doorway to a room
    # with a wooden table and two chairs.
    "nyu": [
        ("the chair", "chair", ""),
        ("the table", "table", ""),
        ("the seat", "chair", ""),
        ("the cabinet", None, "class"),
        ("the wardrobe", None, "class"),
        ("the tv", None, "none"),
        ("the bed", None, "none"),
    ],
    # SUN: an office corridor; doors, filing cabinets, carpet; nothing of COCO's 80 classes.
    "sun": [
        ("the chair", None, "none"),
        ("the door", None, "class"),
        ("the cabinet", None, "class"),
        ("the couch", None, "none"),
    ],
}

#: Requests that name one of two objects of a label, and the side of the image it stands on.
SIDE = {"the yellow chair": "right", "the red office chair": "left"}


def write_recording(enc: str, out: Path) -> None:
    """One frame, identity pose, PrimeSense intrinsics (the folder's README), TUM layout."""
    from capnav.core.frame import Frame
    from capnav.io.depth_formats import decode_depth
    from capnav.io.export import write_tum
    from capnav.io.intrinsics import PRIMESENSE
    from capnav.io.tum import read_rgb

    rgb_name, depth_name = FILES[enc]
    f = Frame(0, read_rgb(SHARED / rgb_name), decode_depth(SHARED / depth_name, enc), PRIMESENSE, np.eye(4))
    write_tum([f], PRIMESENSE, out)


def cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "capnav.cli", *args], capture_output=True, text=True)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", type=Path, default=Path("runs/realframes"))
    ap.add_argument("--detectors", nargs="+", default=["yolo-fastest", "centernet"])
    ap.add_argument("--frames", nargs="+", default=sorted(FILES))
    a = ap.parse_args()
    if not SHARED.is_dir():
        sys.exit(f"needs {SHARED}")
    rows = []
    for enc in a.frames:
        rec = a.out / f"{enc}-tum"
        if not rec.exists():
            write_recording(enc, rec)
        ds = a.out / enc
        if not ds.exists():
            r = cli("import", "auto", str(rec), "-o", str(ds))
            print(f"## import {enc}: rc {r.returncode}\n{r.stdout}{r.stderr}")
            if r.returncode:
                continue
        for det in a.detectors:
            mp = a.out / f"{enc}-{det}.capnav"
            if not mp.exists():
                r = cli("map", str(ds), "-o", str(mp), "--detector", det)
                print(f"## map {enc} {det}: rc {r.returncode}\n{r.stdout[-1500:]}{r.stderr[-1500:]}")
                if r.returncode:
                    continue
                r = cli("caption", str(mp), "--dataset", str(ds))
                print(f"## caption: rc {r.returncode}\n{r.stdout[-800:]}{r.stderr[-800:]}")
            r = cli("objects", str(mp))
            print(f"## objects {enc} {det}\n{r.stdout}{r.stderr[-800:]}")
            for req, want, why in REQUESTS[enc]:
                r = cli("query", str(mp), req, "--json")
                try:
                    res = json.loads(r.stdout)
                except json.JSONDecodeError:
                    res = {"found": False, "error": (r.stdout + r.stderr)[-300:]}
                chosen = res.get("chosen") if res.get("found") else None
                got = chosen.get("label") if chosen else None
                reason = str(res.get("reason", res.get("error", "")))
                ok = got == want
                if ok and chosen and req in SIDE:  # which of two: left or right of the camera (x)
                    ok = (chosen["position"][0] > 0) == (SIDE[req] == "right")
                if want is None and why == "class":
                    ok = ok and "has no" in reason.split(" Other candidates:")[0] and "class" in reason
                nav = ""
                if got is not None:
                    nav_dir = a.out / f"nav-{enc}-{det}"
                    n = cli("navigate", str(mp), req, "-o", str(nav_dir))
                    try:
                        nj = json.loads((nav_dir / "navigate.json").read_text())
                        g, pth = nj.get("goal") or {}, nj.get("path") or {}
                        nav = (f"ok={nj.get('ok')} goal_on_seen_floor={g.get('on_seen_floor')} "
                               f"path_seen_free={pth.get('seen_free_fraction')} {str(nj.get('reason', ''))[:60]}")
                        (nav_dir / "navigate.json").unlink()
                    except (OSError, json.JSONDecodeError):
                        nav = (n.stdout + n.stderr)[-200:].replace("\n", " ")
                rows.append((enc, det, req, want, got, reason[:90], ok, nav))
                print(f"{enc:4} {det:13} {req!r:32} want={want!s:13} got={got!s:13} {'OK ' if ok else 'BAD'} "
                      f"{reason[:80]} | {nav}")
    n_ok = sum(r[6] for r in rows)
    print(f"\n{n_ok} of {len(rows)} right")


if __name__ == "__main__":
    main()
