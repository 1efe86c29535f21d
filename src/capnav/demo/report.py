"""Write the demo's report as Markdown and as a self-contained-folder HTML page.

Pictures are files beside the report (``images/``) so both formats show them; the HTML escapes
every piece of text that came from a model or a user.
"""

from __future__ import annotations

import html
from dataclasses import dataclass, field
from pathlib import Path

from capnav.core.atomic import write_text
from capnav.core.text import shorten


@dataclass
class ReportItem:
    """One instruction and what CapNav did with it."""

    instruction: str
    kind: str  # instruction kind (attribute, superlative, relation, closest, category, absent, user)
    found: bool
    chosen_id: int | None
    chosen_label: str | None
    caption: str | None
    score: float | None
    reason: str
    runners_up: list[str] = field(default_factory=list)
    reached: bool | None = None  # the agent stopped within the reach radius of the chosen object
    correct: bool | None = None  # stopped within 1 m of a meant instance, by the simulator's truth (None: user text)
    right_object: bool | None = None  # the chosen map object lies on a meant instance (truth)
    truth_distance: float | None = None  # m from the stop to the nearest meant instance (truth)
    path_length: float | None = None
    nav_reason: str = ""
    view_png: str | None = None  # path relative to the report folder
    map_png: str | None = None
    timings: dict[str, float] = field(default_factory=dict)
    rejected: bool = False  # the instruction itself was refused (empty, too long, not English); ``reason`` says why


@dataclass
class Report:
    title: str
    summary: list[tuple[str, str]]  # (label, value) rows
    items: list[ReportItem]
    overview_png: str | None = None  # the map CapNav built, objects labelled with their map ids
    truth_png: str | None = None  # the simulator's apartment, truth ids marked "T" (only where truth is the subject)


MAP_CAPTION = ("The map CapNav built: every object boxed and labelled with its map id, the id the answers "
               "below use.")
TRUTH_CAPTION = ("The apartment as the simulator built it (its truth, used only to judge the answers): "
                 "T-numbers are truth ids, not map ids.")


def verdict(it: ReportItem) -> str:
    if it.rejected:
        return f"rejected: {it.reason}"
    if not it.found:
        return "not found" + (" (correct)" if it.correct else " (wrong)" if it.correct is False else "")
    if it.right_object is False:
        return "wrong object"
    if it.correct is False and it.truth_distance is not None:
        return f"right object, but stopped {it.truth_distance:.2f} m from it (success needs 1 m)"
    parts = ["reached" if it.reached else "not reached"]
    if it.right_object:
        parts.append("right object")
    return ", ".join(parts)


def write_markdown(report: Report, path: Path) -> None:
    lines = [f"# {report.title}", ""]
    lines += ["| | |", "|---|---|"] + [f"| {k} | {v} |" for k, v in report.summary] + [""]
    if report.overview_png:
        lines += [f"![map]({report.overview_png})", "", MAP_CAPTION, ""]
    if report.truth_png:
        lines += [f"![apartment]({report.truth_png})", "", TRUTH_CAPTION, ""]
    for i, it in enumerate(report.items, 1):
        lines += [f"## {i}. \"{shorten(it.instruction, 200)}\"", "", f"*{it.kind}* — **{verdict(it)}**", ""]
        if it.found:
            lines += [f"- chosen: object {it.chosen_id} ({it.chosen_label}), score {it.score:.3f}",
                      f"- caption: {it.caption}"]
        lines += [f"- reason: {it.reason}"]
        if it.runners_up:
            lines += ["- runners-up: " + "; ".join(it.runners_up)]
        if it.nav_reason:
            lines += [f"- navigation: {it.nav_reason}" + (f" ({it.path_length:.1f} m)" if it.path_length else "")]
        lines.append("")
        pics = [p for p in (it.view_png, it.map_png) if p]
        if pics:
            lines += [" ".join(f"![]({p})" for p in pics), ""]
    write_text(path, "\n".join(lines))


def write_html(report: Report, path: Path) -> None:
    e = html.escape
    rows = "".join(f"<tr><th>{e(k)}</th><td>{e(v)}</td></tr>" for k, v in report.summary)
    parts = [
        "<!doctype html><html><head><meta charset='utf-8'>",
        f"<title>{e(report.title)}</title>",
        "<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#222}"
        "table{border-collapse:collapse}th,td{border:1px solid #ccc;padding:4px 8px;text-align:left}"
        ".item{border-top:2px solid #ddd;margin-top:1.5em;padding-top:.5em}.ok{color:#1a7f37}.bad{color:#b42318}"
        ".pics img{max-height:360px;margin-right:8px;border:1px solid #ccc}</style></head><body>",
        f"<h1>{e(report.title)}</h1><table>{rows}</table>",
    ]
    if report.overview_png:
        parts.append(f"<figure><img src='{e(report.overview_png)}' style='max-width:600px'>"
                     f"<figcaption>{e(MAP_CAPTION)}</figcaption></figure>")
    if report.truth_png:
        parts.append(f"<figure><img src='{e(report.truth_png)}' style='max-width:600px'>"
                     f"<figcaption>{e(TRUTH_CAPTION)}</figcaption></figure>")
    for i, it in enumerate(report.items, 1):
        good = (it.correct is not False) and (it.reached is not False)
        parts.append(f"<div class='item'><h2>{i}. &ldquo;{e(shorten(it.instruction, 200))}&rdquo;</h2>")
        css = "ok" if good else "bad"
        parts.append(f"<p><i>{e(it.kind)}</i> &mdash; <b class='{css}'>{e(verdict(it))}</b></p><ul>")
        if it.found:
            parts.append(f"<li>chosen: object {it.chosen_id} ({e(str(it.chosen_label))}), score {it.score:.3f}</li>")
            parts.append(f"<li>caption: <q>{e(str(it.caption))}</q></li>")
        parts.append(f"<li>reason: {e(it.reason)}</li>")
        if it.runners_up:
            parts.append("<li>runners-up: " + e("; ".join(it.runners_up)) + "</li>")
        if it.nav_reason:
            extra = f" ({it.path_length:.1f} m)" if it.path_length else ""
            parts.append(f"<li>navigation: {e(it.nav_reason)}{extra}</li>")
        parts.append("</ul><div class='pics'>")
        parts += [f"<img src='{e(p)}'>" for p in (it.view_png, it.map_png) if p]
        parts.append("</div></div>")
    parts.append("</body></html>")
    write_text(path, "\n".join(parts))
