"""The Markdown report: the paper's Table 1 and Table 2 laid out with our numbers beside theirs,
the description-protocol table the paper lacks, a details table and failure cases."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from capnav.eval import failure_modes
from capnav.eval.metrics import SubgoalRecord, Summary
from capnav.eval.paper import PAPER_SETUP, TABLE1, TABLE2

#: Display order of methods in the tables (unknown names follow in the order given).
ORDER = ("lmnav", "lm-nav", "zson", "cow", "random-object", "category-only", "vlmaps",
         "capnav-no-verify", "capnav-no-heuristic", "capnav")


def _key(name: str) -> str:
    return name.lower().replace("_", "-")


def paper_row(method: str) -> Any:
    """Paper Table 1 row for one of our method names (``lm-nav`` and ``lmnav`` both match)."""
    k = _key(method)
    return TABLE1.get(k) or TABLE1.get(k.replace("-", ""))


def pct(x: float | None) -> str:
    """A fraction as a percentage with one decimal; "–" when there is none."""
    return "–" if x is None else f"{100.0 * x:.1f}"


def _with_ci(s: Summary) -> str:
    """Independent success with its bootstrap 95% interval over episodes, when there is one."""
    if not s.independent_ci:
        return pct(s.independent)
    lo, hi = s.independent_ci
    return f"{pct(s.independent)} [{pct(lo)}-{pct(hi)}]"


def _sorted(summaries: Sequence[Summary]) -> list[Summary]:
    rank = {m: i for i, m in enumerate(ORDER)}
    return sorted(summaries, key=lambda s: (rank.get(_key(s.method), len(ORDER)), s.method))


def table1(summaries: Sequence[Summary], protocol: str = "label") -> list[str]:
    """In-a-row success for 1..4 subgoals and independent success, under the paper's rule and the
    strict one; the paper's numbers beside ours only for its own (label-only) protocol."""
    paper_cols = protocol == "label"
    lines = ["| Method | 1 | 2 | 3 | 4 | Indep. [95% CI] | SPL | Strict 1 / 2 / 3 / 4 | Strict indep. "
             "| Strict, in its room " + ("| Paper 1 / 2 / 3 / 4 | Paper indep. |" if paper_cols else "|"),
             "|---|---:|---:|---:|---:|---:|---:|---|---:|---:|" + ("---|---:|" if paper_cols else "")]
    for s in _sorted([s for s in summaries if s.protocol == protocol]):
        p = paper_row(s.method)
        paper = " / ".join(f"{v:g}" for v in p.in_a_row) if p else "–"
        paper_ind = f"{p.independent:g}" if p else "–"
        row = " | ".join(pct(v) for v in s.in_a_row)
        strict = " / ".join(pct(v) for v in s.in_a_row_strict) if s.in_a_row_strict else "–"
        lines.append(f"| {s.method} | {row} | {_with_ci(s)} | {pct(s.spl)} | {strict} "
                     f"| {pct(s.independent_strict)} | {pct(s.independent_room)} |"
                     + (f" {paper} | {paper_ind} |" if paper_cols else ""))
    return lines


def _single(summaries: Sequence[Summary], protocol: str) -> list[str]:
    """Success, SPL and strict success of one-subgoal episodes (the free-phrasing protocol)."""
    lines = ["| Method | Success [95% CI] | SPL | Strict success | Strict, in its room |", "|---|---:|---:|---:|---:|"]
    for s in _sorted([s for s in summaries if s.protocol == protocol]):
        lines.append(f"| {s.method} | {_with_ci(s)} | {pct(s.spl)} | {pct(s.independent_strict)} "
                     f"| {pct(s.independent_room)} |")
    return lines


def table2(summaries: Sequence[Summary]) -> list[str]:
    """Ablations: full-chain success and subgoal success, both protocols, paper beside ours."""
    by = {(s.method, s.protocol): s for s in summaries}
    lines = ["| Method | SR (label) | Subgoal SR (label) | SR (description) | Subgoal SR (description) "
             "| Paper SR | Paper subgoal SR |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for name, (label, psr, psub) in TABLE2.items():
        lab, des = by.get((name, "label")), by.get((name, "description"))
        if lab is None and des is None:
            continue
        cells = [pct(s.in_a_row[-1] if s else None) + " | " + pct(s.independent if s else None) for s in (lab, des)]
        lines.append(f"| {name} ({label}) | {cells[0]} | {cells[1]} | {psr:.1f} | {psub:.1f} |")
    return lines


def sequences(records: Sequence[SubgoalRecord], protocol: str = "phrasing") -> list[str]:
    """Requests of several goals ("the sink, then the bed"): how many had every goal reached, per
    method (a request counts only when all its goals succeeded). Empty when there are none."""
    by: dict[tuple[str, str], list[bool]] = {}
    for r in records:
        if r.protocol == protocol:
            by.setdefault((r.method, r.episode_id), []).append(bool(r.success))
    chains = {k: v for k, v in by.items() if len(v) > 1}
    if not chains:
        return []
    lines = ["", "Requests of several goals, every goal reached:", "", "| Method | Requests | All goals reached |",
             "|---|---:|---:|"]
    for m in sorted({m for m, _ in chains}):
        done = [all(v) for (mm, _), v in chains.items() if mm == m]
        lines.append(f"| {m} | {len(done)} | {sum(done)} |")
    return lines


def by_kind(records: Sequence[SubgoalRecord], protocol: str = "phrasing") -> list[str]:
    """Success per instruction kind and method (the phrasing protocol's kinds come from its file)."""
    recs = [r for r in records if r.protocol == protocol]
    methods = [m for m in dict.fromkeys(r.method for r in recs)]
    methods.sort(key=lambda m: (ORDER.index(_key(m)) if _key(m) in ORDER else len(ORDER), m))
    kinds = sorted({r.kind for r in recs})
    lines = ["| Kind | n | " + " | ".join(methods) + " |", "|---|---:|" + "---:|" * len(methods)]
    for k in kinds:
        cells = []
        for m in methods:
            rs = [r for r in recs if r.method == m and r.kind == k]
            ok = sum(r.success for r in rs)
            strict = sum(bool(r.success_strict) for r in rs)
            cells.append(f"{ok}/{len(rs)} ({strict} strict)")
        n = len([r for r in recs if r.kind == k and r.method == methods[0]])
        lines.append(f"| {k} | {n} | " + " | ".join(cells) + " |")
    return lines


def details(summaries: Sequence[Summary]) -> list[str]:
    lines = ["| Method | Protocol | Episodes | Subgoals | Indep. | SPL | Retrieval top-1 | Goal claimed "
             "| Path / subgoal (m) | Query time mean / p50 (ms) | Crashes |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for s in _sorted(summaries):
        lines.append(f"| {s.method} | {s.protocol} | {s.episodes} | {s.subgoals} | {pct(s.independent)} "
                     f"| {pct(s.spl)} | {pct(s.retrieval_top1)} | {pct(s.found_rate)} | {s.path_length:.2f} "
                     f"| {1e3 * s.query_time_mean_s:.1f} / {1e3 * s.query_time_p50_s:.1f} | {s.crashes} |")
    return lines


def standings(summaries: Sequence[Summary], protocol: str, reference: str = "capnav") -> list[str]:
    """One sentence per success rule naming the methods that tie or beat ``reference``: a table
    where a baseline ties CapNav (category-only on bare category goals) says so in words."""
    rows = {s.method: s for s in summaries if s.protocol == protocol}
    ref = rows.get(reference)
    if ref is None or len(rows) < 2:
        return []
    out = []
    for rule, get in (("paper rule", lambda s: s.independent), ("strict", lambda s: s.independent_strict)):
        r = get(ref)
        if r is None:
            continue
        others = [(m, get(s)) for m, s in rows.items() if m != reference and get(s) is not None]
        ties = [m for m, v in others if abs(v - r) < 5e-4]
        above = [f"{m} ({pct(v)})" for m, v in others if v - r >= 5e-4]
        below = [m for m, v in others if r - v >= 5e-4]
        out.append(f"- {rule}: {reference} {pct(r)}% of subgoals; "
                   f"tied by {', '.join(ties) if ties else 'no other method'}; "
                   f"above it: {', '.join(above) if above else 'none'}; below it: {len(below)} of {len(others)}.")
    return ["", "Standing against CapNav (independent subgoal success):", "", *out] if out else []


def render(summaries: Sequence[Summary], config: Mapping[str, Any],
           failures: Sequence[Mapping[str, Any]] = (), timings: Mapping[str, float] | None = None,
           notes: Mapping[str, str] | None = None, records: Sequence[SubgoalRecord] = ()) -> str:
    """The whole report as Markdown. ``failures`` items: method, protocol, episode_id, index, text,
    reason, distance_to_goal, picture (relative path or empty); ``records`` (optional) give the
    table of failure classes."""
    out = ["# CapNav benchmark report", ""]
    out.append(f"capnav {config.get('version', '?')} (commit {config.get('commit', '?')}), seed {config.get('seed')}, "
               f"{config.get('scenes')} apartments (scene seeds {config.get('scene_seeds')}), "
               + (f"episodes from `{config['instructions']}`, " if config.get("instructions") else
                  f"{config.get('episodes_per_scene')} episodes per apartment and protocol, ")
               + f"detector `{config.get('detector', '?')}`, embedder `{config.get('embedder', '?')}`.")
    out.append("")
    if config.get("resumed_scenes"):
        out.append(f"Resumed run: apartments {config['resumed_scenes']} were finished in an earlier sitting and "
                   f"reused; apartments were computed at commit(s) {', '.join(config.get('scene_commits', []))}. "
                   "The wall clock below is this sitting's; the stage times cover every apartment.")
        out.append("")
    track = config.get("track", "default houses, primitives furniture, sim:default detector")
    out.append(f"Track: **{track}**; every table below belongs to this track.")
    out.append("")
    out.append(f"Command: `{config.get('command', 'capnav eval')}`")
    out.append("")
    out.append(f"The paper: {PAPER_SETUP['scenes']} Matterport3D scenes in Habitat, {PAPER_SETUP['episodes']} "
               f"episodes, {PAPER_SETUP['subgoals']} subgoals, {PAPER_SETUP['categories']} categories, "
               "Detic + LSeg + Gemini + BGE-M3. Ours: procedural apartments in pybullet, a simulated detector "
               "with a noise model, offline captions and a MiniLM embedder. Compare methods within a table; "
               "absolute numbers are not comparable across the two setups.")
    out += ["", "Success is the paper's rule (the agent stops within 1 m of a goal instance's footprint); "
            "*strict* also asks that it sees the object: a straight line from the stop point to the "
            "footprint that no wall and no object 1 m or taller crosses (`capnav.sim.sightline`); *strict, in its "
            "room* also asks that the stop point is in the room the object stands in. The interval beside "
            "independent success is a bootstrap 95% interval over episodes.", ""]
    protocols = {s.protocol for s in summaries}  # a table only for the protocols this run measured
    if "label" in protocols:
        out += ["", "## Table 1: multi-object navigation, label-only protocol (success %, in a row)", ""]
        out += table1(summaries, "label")
        out += standings(summaries, "label")
    if protocols & {"label", "description"}:
        out += ["", "## Table 2: ablations (full-chain success rate and subgoal success rate, %)", ""]
        out += table2(summaries)
    if "description" in protocols:
        out += ["", "## Description protocol: reach the one described instance among lookalikes (%)", "",
                "Not in the paper, so no paper numbers beside it.", ""]
        out += table1(summaries, "description")
        out += standings(summaries, "description")
    if "phrasing" in protocols:
        out += ["", "## Free phrasings: hand-written instructions (success %)", "",
                f"Instructions from `{config.get('instructions', 'a file')}`, one subgoal per goal, judged like the "
                "description protocol; an absent target succeeds when the method answers 'not found'.", ""]
        out += _single(summaries, "phrasing")  # one subgoal per episode: no chains to count
        out += standings(summaries, "phrasing")
        if records:
            out += ["", "Successes per kind (paper rule, with the strict count):", ""]
            out += by_kind(records, "phrasing")
            out += sequences(records, "phrasing")
    out += ["", "## Details", ""]
    out += details(summaries)
    if records:
        out += ["", "## Why subgoals failed (failed subgoals per class)", "",
                "Judged by the harness: *wrong object* = the chosen target is not at a goal instance; "
                "*right object, stopped too far* = it is, but the agent ended more than 1 m away.", ""]
        out += failure_modes.table(records, ORDER)
    if notes:
        out += ["", "## Methods: what each one is, and how it differs from its original", ""]
        # Methods implemented in one module (CapNav and its ablations) share a note: say it once.
        by_text: dict[str, list[str]] = {}
        for name, text in notes.items():
            by_text.setdefault(" ".join(text.split()), []).append(name)
        out += [f"- **{' / '.join(names)}**: {text}" for text, names in by_text.items()]
    if timings:
        out += ["", "## Where the time went (s, summed over workers)", "",
                "| Stage | Seconds |", "|---|---:|"]
        out += [f"| {k} | {v:.1f} |" for k, v in timings.items()]
    if failures:
        out += ["", "## Failure cases", ""]
        for f in failures:
            pic = f" ![]({f['picture']})" if f.get("picture") else ""
            out.append(f"- **{f['method']}** / {f['protocol']} / {f['episode_id']} #{f['index']}: "
                       f"\"{f['text']}\" stopped {f['distance_to_goal']:.2f} m from the goal; {f['reason']}{pic}")
    return "\n".join(out) + "\n"
