"""Write the demo's report as Markdown and as a self-contained-folder HTML page.

Pictures are files beside the report (``images/``) so both formats show them; the HTML escapes
every piece of text that came from a model or a user.
"""

from __future__ import annotations

import html
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

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
    runners_up: list[str] = field(default_factory=list)  # "id label" of the runners-up, in decision order
    #: The chosen object and the runners-up: id, label, similarity, verifier, final, why, chosen.
    candidates: list[dict[str, Any]] = field(default_factory=list)
    reached: bool | None = None  # the agent stopped within the reach radius of the chosen object
    correct: bool | None = None  # stopped within 1 m of a meant instance, by the simulator's truth (None: user text)
    right_object: bool | None = None  # the chosen map object lies on a meant instance (truth)
    truth_distance: float | None = None  # m from the stop to the nearest meant instance (truth)
    in_room: bool | None = None  # the stop is in the room that instance stands in (truth)
    facing_deg: float | None = None  # how far the final heading turns away from it (0: facing it)
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
    if it.in_room is not None:
        parts.append("in its room" if it.in_room else "outside its room")
    if it.facing_deg is not None:
        parts.append("facing it" if it.facing_deg == 0.0 else f"turned {it.facing_deg:.0f}° away from it")
    return ", ".join(parts)


#: The candidate table's columns: one scale each, named, and what it means.
SCORE_COLUMNS = (
    ("similarity", "cosine similarity of the object's caption to the instruction (eq. 16), -1..1"),
    ("verifier", "the verifier's score of the object for this instruction (higher is better; a stand-in "
                 "category scores lower; 'rejected' when it refused the object, '-' when it did not judge it)"),
    ("final", "the score the decision compared: the verifier's where it judged the object, else the similarity; "
              "a predicate (closest, largest, a room, next to ...) orders the candidates before any score"),
)


def _num(v: float | None) -> str:
    return "-" if v is None else f"{v:.2f}"


def candidate_rows(it: ReportItem) -> list[tuple[str, str, str, str, str]]:
    """(object, similarity, verifier, final, outcome) per candidate, the chosen one first."""
    rows = []
    for c in it.candidates:
        why = str(c.get("why") or "")
        rejected = why.startswith("rejected")
        ver = "rejected" if rejected else _num(c.get("verifier"))
        final = "-" if rejected else _num(c.get("final"))
        rows.append((f"{c['id']} {c['label']}", _num(c.get("similarity")), ver, final,
                     "chosen" if c.get("chosen") else why))
    return rows


def _picture_md(p: str, alt: str) -> str:
    return f"[![{alt}]({p})]({p})"


def write_markdown(report: Report, path: Path) -> None:
    lines = [f"# {report.title}", ""]
    lines += ["| | |", "|---|---|"] + [f"| {k} | {v} |" for k, v in report.summary] + [""]
    if report.overview_png:
        lines += [_picture_md(report.overview_png, "map"), "", MAP_CAPTION, ""]
    if report.truth_png:
        lines += [_picture_md(report.truth_png, "apartment"), "", TRUTH_CAPTION, ""]
    lines += ["Scores in the candidate tables: " + "; ".join(f"**{n}**: {d}" for n, d in SCORE_COLUMNS) + ".", ""]
    for i, it in enumerate(report.items, 1):
        lines += [f"## {i}. \"{shorten(it.instruction, 200)}\"", "", f"*{it.kind}* — **{verdict(it)}**", ""]
        if it.rejected:
            continue
        if it.found:
            lines += [f"- chosen: object {it.chosen_id} ({it.chosen_label})", f"- caption: {it.caption}"]
        lines += [f"- reason: {it.reason}"]
        if it.nav_reason:
            lines += [f"- navigation: {it.nav_reason}" + (f" ({it.path_length:.1f} m)" if it.path_length else "")]
        lines.append("")
        rows = candidate_rows(it)
        if rows:
            lines += ["| object | similarity | verifier | final | outcome |", "|---|---:|---:|---:|---|"]
            lines += [f"| {' | '.join(r)} |" for r in rows] + [""]
        pics = [(p, a) for p, a in ((it.view_png, "captioning view"), (it.map_png, "navigation")) if p]
        if pics:
            lines += [" ".join(_picture_md(p, a) for p, a in pics), ""]
    write_text(path, "\n".join(lines))


_CSS = ("body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222;line-height:1.4}"
        "table{border-collapse:collapse;margin:.5em 0}th,td{border:1px solid #ccc;padding:4px 8px;text-align:left;"
        "vertical-align:top}td.n{text-align:right;font-variant-numeric:tabular-nums}td.o{white-space:nowrap}"
        ".item{border-top:2px solid #ddd;margin-top:1.5em;padding-top:.5em}.ok{color:#1a7f37}.bad{color:#b42318}"
        "tr.chosen td{background:#fdecea;font-weight:bold}"
        ".pics a{display:inline-block;margin-right:8px;vertical-align:top}"
        ".pics img{height:260px;border:1px solid #ccc}.pics a span{display:block;font-size:85%;color:#555}"
        "figure img{max-width:100%;border:1px solid #ccc}dl.legend dt{font-weight:bold;float:left;width:6.5em}"
        "dl.legend dd{margin-left:7em;margin-bottom:.3em}")


def _picture_html(p: str, label: str, e: Callable[[str], str]) -> str:
    return (f"<a href='{e(p)}' title='open full size'><img src='{e(p)}' alt='{e(label)}'>"
            f"<span>{e(label)} (click for full size)</span></a>")


def write_html(report: Report, path: Path) -> None:
    e = html.escape
    rows = "".join(f"<tr><th>{e(k)}</th><td>{e(v)}</td></tr>" for k, v in report.summary)
    parts = [
        "<!doctype html><html><head><meta charset='utf-8'>",
        "<meta name='viewport' content='width=device-width, initial-scale=1'>",
        f"<title>{e(report.title)}</title><style>{_CSS}</style></head><body>",
        f"<h1>{e(report.title)}</h1><table>{rows}</table>",
    ]
    for png, cap in ((report.overview_png, MAP_CAPTION), (report.truth_png, TRUTH_CAPTION)):
        if png:
            parts.append(f"<figure><a href='{e(png)}'><img src='{e(png)}' style='max-width:640px' alt=''></a>"
                         f"<figcaption>{e(cap)}</figcaption></figure>")
    parts.append("<h2>How to read the candidate tables</h2><dl class='legend'>"
                 + "".join(f"<dt>{e(n)}</dt><dd>{e(d)}</dd>" for n, d in SCORE_COLUMNS) + "</dl>")
    for i, it in enumerate(report.items, 1):
        good = (it.correct is not False) and (it.reached is not False) and not it.rejected
        parts.append(f"<div class='item' id='item-{i}'><h2>{i}. &ldquo;{e(shorten(it.instruction, 200))}&rdquo;</h2>")
        css = "ok" if good else "bad"
        parts.append(f"<p><i>{e(it.kind)}</i> &mdash; <b class='{css}'>{e(verdict(it))}</b></p>")
        if it.rejected:
            parts.append("</div>")
            continue
        parts.append("<ul>")
        if it.found:
            parts.append(f"<li>chosen: object {it.chosen_id} ({e(str(it.chosen_label))})</li>")
            parts.append(f"<li>caption: <q>{e(str(it.caption))}</q></li>")
        parts.append(f"<li>reason: {e(it.reason)}</li>")
        if it.nav_reason:
            extra = f" ({it.path_length:.1f} m)" if it.path_length else ""
            parts.append(f"<li>navigation: {e(it.nav_reason)}{extra}</li>")
        parts.append("</ul>")
        cand = candidate_rows(it)
        if cand:
            head = "".join(f"<th>{h}</th>" for h in ("object", "similarity", "verifier", "final", "outcome"))
            body = "".join(
                f"<tr class='{'chosen' if r[4] == 'chosen' else ''}'><td class='o'>{e(r[0])}</td>"
                f"<td class='n'>{e(r[1])}</td><td class='n'>{e(r[2])}</td><td class='n'>{e(r[3])}</td>"
                f"<td>{e(r[4])}</td></tr>" for r in cand)
            parts.append(f"<table class='cands'><tr>{head}</tr>{body}</table>")
        parts.append("<div class='pics'>")
        parts += [_picture_html(p, label, e) for p, label in
                  ((it.view_png, "the view chosen for captioning"), (it.map_png, "the map, plan and drive")) if p]
        parts.append("</div></div>")
    parts.append("</body></html>")
    write_text(path, "\n".join(parts))
