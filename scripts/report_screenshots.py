"""Screenshots of the demo's report for the docs, taken by the system Chromium (headless).

    .venv/bin/capnav demo --out runs/demo
    .venv/bin/python scripts/report_screenshots.py runs/demo -o docs/demo

Writes ``report.png`` (the top of the report: summary, map, how to read the scores),
``report_item.png`` (the first answer: reason, candidate table, thumbnails) and copies the first
answer's captioning view and navigation picture as ``view.png`` and ``nav.png``.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import tempfile
from pathlib import Path

CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                  "--no-first-run", "--hide-scrollbars"]


def chromium() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        if path := shutil.which(name):
            return path
    raise SystemExit("no chromium found: apt-get install chromium")


def screenshot(url: str, out: Path, width: int, height: int) -> Path:
    """One headless Chromium screenshot of ``url`` at ``width`` x ``height`` CSS pixels."""
    with tempfile.TemporaryDirectory() as profile:
        subprocess.run([chromium(), *CHROMIUM_FLAGS, f"--user-data-dir={profile}", f"--window-size={width},{height}",
                        f"--screenshot={out}", url], check=True, capture_output=True, timeout=120)
    if not out.is_file() or out.stat().st_size == 0:
        raise SystemExit(f"chromium wrote no screenshot for {url}")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("demo", type=Path, help="the folder `capnav demo --out` wrote")
    ap.add_argument("-o", "--out", type=Path, default=Path("docs/demo"))
    ap.add_argument("--item", type=int, default=1, help="which answer to show (1-based)")
    args = ap.parse_args()
    report = (args.demo / "report.html").resolve()
    if not report.is_file():
        raise SystemExit(f"{report} not found: run `capnav demo --out {args.demo}` first")
    args.out.mkdir(parents=True, exist_ok=True)
    url = report.as_uri()
    print(screenshot(url, args.out / "report.png", 1200, 1500))
    # the answer alone: the report with every other part hidden, so the shot starts at its heading
    with tempfile.NamedTemporaryFile("w", suffix=".html", dir=report.parent, delete=False) as f:
        page = report.read_text(encoding="utf-8")
        f.write(page.replace("</style>", f"body>*{{display:none}}body>#item-{args.item}{{display:block}}</style>", 1))
        one = Path(f.name)
    try:
        print(screenshot(one.as_uri(), args.out / "report_item.png", 1200, 1100))
    finally:
        one.unlink()
    k = f"{args.item:02d}"
    for src, dst in ((f"images/{k}_view.png", "view.png"), (f"images/{k}_nav.png", "nav.png")):
        if (args.demo / src).is_file():
            shutil.copyfile(args.demo / src, args.out / dst)
            print(args.out / dst)


if __name__ == "__main__":
    main()
