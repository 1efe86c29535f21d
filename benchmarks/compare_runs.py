"""Put several `capnav eval` runs side by side: one Markdown table per protocol, one column group
per run (the paper's success rule and the strict one), and a header table saying which track,
size, commit and episodes each run is, and how long it took.

The README's tables that compare tracks (house size, furniture, detector, hand-written
instructions) are printed by this script from the runs' ``results.json``, so each figure traces
back to the `capnav eval` command recorded in it.

    python benchmarks/compare_runs.py runs/eval=default runs/eval-large=large [--protocols label,description]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from capnav.eval.report import pct

ORDER = ("capnav", "capnav-no-heuristic", "capnav-no-verify", "category-only", "vlmaps", "cow", "zson",
         "lmnav", "random-object")


def load(arg: str) -> tuple[str, dict[str, Any]]:
    """``FOLDER[=LABEL]`` -> (label, results.json); the label defaults to the folder's name."""
    folder, _, label = arg.partition("=")
    path = Path(folder) / "results.json"
    if not path.is_file():
        raise SystemExit(f"error: {path} does not exist (run `capnav eval --out {folder}` first)")
    return label or Path(folder).name, json.loads(path.read_text())


def cpu_minutes(res: dict[str, Any]) -> float:
    """Stage seconds summed over workers (wall clock inside each worker), in minutes."""
    t = res.get("timings", {})
    return sum(v for k, v in t.items() if not k.startswith("wall")) / 60.0


def header(runs: list[tuple[str, dict[str, Any]]]) -> list[str]:
    lines = ["| Run | Track | Commit | Apartments (seeds) | Episodes | Subgoals | Wall (min) "
             "| Stage time (min, summed over workers) | Command |",
             "|---|---|---|---|---:|---:|---:|---:|---|"]
    for label, r in runs:
        seeds = r.get("scene_seeds") or []
        span = f"{len(seeds)} ({seeds[0]}-{seeds[-1]})" if seeds else "–"
        subgoals = sum(s["subgoals"] for s in r["summaries"] if s["method"] == "capnav")
        episodes = sum(s["episodes"] for s in r["summaries"] if s["method"] == "capnav")
        # A resumed run: the apartments' own commits, and a wall clock that is only the last sitting's.
        commit = ", ".join(r.get("scene_commits") or [r.get("commit", "–")])
        wall = f"{r['seconds'] / 60:.1f}" + (" (last sitting; resumed)" if r.get("resumed_scenes") else "")
        lines.append(f"| {label} | {r.get('track', '–')} | {commit} | {span} | {episodes} | {subgoals} "
                     f"| {wall} | {cpu_minutes(r):.1f} | `{r.get('command', '')}` |")
    return lines


def table(runs: list[tuple[str, dict[str, Any]]], protocol: str) -> list[str]:
    """Method rows; per run: independent success (paper rule / strict) and the 4-in-a-row chain."""
    by = [{s["method"]: s for s in r["summaries"] if s["protocol"] == protocol} for _, r in runs]
    methods = [m for m in ORDER if any(m in b for b in by)] + sorted({m for b in by for m in b} - set(ORDER))
    if not methods:
        return []
    mean = len(runs) > 1
    head = "| Method | " + " | ".join(f"{label}: indep. [95% CI] / strict / strict in its room / 4 in a row"
                                      for label, _ in runs) \
        + (" | mean indep. of the runs |" if mean else " |")
    lines = [f"**{protocol}** (subgoal success %, paper rule with its bootstrap 95% interval over episodes / strict; "
             "strict and stopped in the object's room; full 4-subgoal chains, paper rule)", "", head,
             "|---|" + "---:|" * (len(runs) + mean)]
    for m in methods:
        cells = []
        for b in by:
            s = b.get(m)
            ci = s.get("independent_ci") if s is not None else None
            cells.append("–" if s is None else
                         f"{pct(s['independent'])}" + (f" [{pct(ci[0])}-{pct(ci[1])}]" if ci else "")
                         + f" / {pct(s.get('independent_strict'))} / {pct(s.get('independent_room'))} / "
                         f"{pct(s['in_a_row'][-1] if s['in_a_row'] else None)}")
        if mean:
            vals = [b[m]["independent"] for b in by if m in b]
            cells.append(pct(sum(vals) / len(vals)) if vals else "–")
        lines.append(f"| {m} | " + " | ".join(cells) + " |")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", help="run folders of `capnav eval`, each optionally =LABEL")
    ap.add_argument("--protocols", default="label,description,phrasing")
    args = ap.parse_args()
    runs = [load(a) for a in args.runs]
    out = header(runs)
    for p in (p.strip() for p in args.protocols.split(",")):
        t = table(runs, p)
        if t:
            out += ["", *t]
    print("\n".join(out))


if __name__ == "__main__":
    main()
