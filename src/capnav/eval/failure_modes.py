"""Why a subgoal failed, read from its record: the harness's judgement, not the method's own story.

Success rates say how often a method fails; this says how. Each failed subgoal falls in exactly
one class, decided from what the harness measured (``found``, ``retrieval_correct``, ``error``)
and, for the two ways of giving up, the method's reason:

- ``crashed``: the method raised (scored as a failure, error kept in the record);
- ``timeout``: the action budget ran out (reason starts with "timeout");
- ``nothing found``: the method reported that no object answers the goal;
- ``wrong object``: it chose a target that is not at a goal instance (a lookalike, a confusion);
- ``right object, stopped too far``: the target was right but the agent ended > 1 m from it.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Sequence

from capnav.eval.metrics import SubgoalRecord

MODES: tuple[str, ...] = ("timeout", "nothing found", "wrong object", "right object, stopped too far", "crashed")


def failure_mode(r: SubgoalRecord) -> str | None:
    """The class of a failed subgoal (see the module docstring); None for a success."""
    if r.success:
        return None
    if r.error:
        return "crashed"
    if r.reason.startswith("timeout"):
        return "timeout"
    if not r.found:
        return "nothing found"
    if r.retrieval_correct:
        return "right object, stopped too far"
    return "wrong object"


def count_modes(records: Iterable[SubgoalRecord]) -> dict[tuple[str, str], Counter[str]]:
    """Failure classes per (method, protocol), in first-seen order; successes are not counted."""
    out: dict[tuple[str, str], Counter[str]] = {}
    for r in records:
        c = out.setdefault((r.method, r.protocol), Counter())
        mode = failure_mode(r)
        if mode is not None:
            c[mode] += 1
    return out


def table(records: Sequence[SubgoalRecord], order: Sequence[str] = ()) -> list[str]:
    """Markdown table: failed subgoals per class, one row per (protocol, method)."""
    counts = count_modes(records)
    rank = {m: i for i, m in enumerate(order)}
    keys = sorted(counts, key=lambda k: (k[1], rank.get(k[0], len(rank)), k[0]))
    lines = ["| Protocol | Method | Failed | " + " | ".join(m.capitalize() for m in MODES) + " |",
             "|---|---|---:|" + "---:|" * len(MODES)]
    for method, protocol in keys:
        c = counts[(method, protocol)]
        lines.append(f"| {protocol} | {method} | {sum(c.values())} | " + " | ".join(str(c[m]) for m in MODES) + " |")
    return lines
