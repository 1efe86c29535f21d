"""The Markdown report: paper numbers beside ours, every table present."""

from __future__ import annotations

from capnav.eval.metrics import Summary
from capnav.eval.report import paper_row, render


def summ(method: str, protocol: str, chain: list[float], indep: float) -> Summary:
    return Summary(method=method, protocol=protocol, episodes=2, subgoals=8, in_a_row=chain, independent=indep,
                   spl=0.5, path_length=3.0, retrieval_top1=0.75, query_time_mean_s=0.004, query_time_p50_s=0.003,
                   found_rate=1.0)


def test_render_tables() -> None:
    sums = [summ("capnav", "label", [1.0, 0.5, 0.5, 0.25], 0.625), summ("vlmaps", "label", [0.5, 0.0, 0.0, 0.0], 0.4),
            summ("capnav", "description", [0.5, 0.5, 0.0, 0.0], 0.5),
            summ("capnav-no-verify", "label", [0.5, 0.5, 0.0, 0.0], 0.5)]
    md = render(sums, {"seed": 3, "version": "0.1.0", "commit": "abc", "scenes": 1, "scene_seeds": [3000],
                       "episodes_per_scene": 2}, [{"method": "vlmaps", "protocol": "label", "episode_id": "e",
                                                   "index": 1, "text": "sofa", "reason": "wrong sofa",
                                                   "distance_to_goal": 2.5, "picture": "pictures/x.png"}],
                {"map": 1.0}, {"vlmaps": "VLMaps-style:\n  dense features."})
    lines = md.splitlines()
    row = next(ln for ln in lines if ln.startswith("| capnav |"))
    # ours 100 / 50 / 50 / 25 beside the paper's 62 / 40 / 22 / 14
    assert "100.0 | 50.0 | 50.0 | 25.0 | 62.5" in row and "62 / 40 / 22 / 14" in row and "56.6" in row
    vl = next(ln for ln in lines if ln.startswith("| vlmaps |"))
    assert "46 / 27 / 16 / 5" in vl
    # Table 2: full-chain SR and subgoal SR beside the paper's 15.4 / 56.6 and 7.7 / 51.9
    t2 = next(ln for ln in lines if ln.startswith("| capnav (CapNav (full))"))
    assert "| 25.0 | 62.5 | 0.0 | 50.0 | 15.4 | 56.6 |" in t2
    t2b = next(ln for ln in lines if ln.startswith("| capnav-no-verify ("))
    assert "| – | – | 7.7 | 51.9 |" in t2b
    assert "- **vlmaps**: VLMaps-style: dense features." in md
    assert "## Description protocol" in md and "![](pictures/x.png)" in md and "seed 3" in md
    # vlmaps comes before capnav in Table 1 (baselines first, as in the paper)
    assert lines.index(vl) < lines.index(row)


def test_paper_row_aliases() -> None:
    assert paper_row("lm-nav") is paper_row("lmnav") is not None
    assert paper_row("category-only") is None


def _rec(method: str, success: bool, found: bool, correct: bool | None, reason: str = "", error: str = "",
         protocol: str = "description"):  # type: ignore[no-untyped-def]
    from capnav.eval.metrics import SubgoalRecord

    return SubgoalRecord(method=method, protocol=protocol, scene_seed=0, episode_id="e", index=0, text="t",
                         category="sofa", target_ids=[1], kind="attribute", success=success, distance_to_goal=2.0,
                         path_length=1.0, shortest_path=1.0, start_xy=(0.0, 0.0), stop_xy=(1.0, 0.0), found=found,
                         retrieval_correct=correct, query_time_s=0.0, steps=0, reason=reason, error=error)


def test_failure_classes_and_their_table() -> None:
    from capnav.eval.failure_modes import MODES, failure_mode, table

    recs = [_rec("cow", True, True, True), _rec("cow", False, False, None, "timeout: 200 actions"),
            _rec("cow", False, True, False, "sofa seen"), _rec("cow", False, True, True, "stopped short"),
            _rec("cow", False, False, None, "not found: nothing left"), _rec("cow", False, True, True, "", "boom"),
            _rec("lmnav", False, True, None, "timeout on the route")]
    assert [failure_mode(r) for r in recs] == [None, "timeout", "wrong object", "right object, stopped too far",
                                               "nothing found", "crashed", "timeout"]
    lines = table(recs, ["lmnav", "cow"])
    assert lines[0].count("|") == len(MODES) + 4
    assert lines[2] == "| description | lmnav | 1 | 1 | 0 | 0 | 0 | 0 |"  # order given: lmnav first
    assert lines[3] == "| description | cow | 5 | 1 | 1 | 1 | 1 | 1 |"  # the success is not counted
    md = render([summ("cow", "description", [0.5, 0.0, 0.0, 0.0], 0.2)], {"seed": 0}, records=recs)
    assert "## Why subgoals failed" in md and "| description | cow | 5 |" in md


def test_a_baseline_that_ties_capnav_is_named() -> None:
    """Category-only equal to CapNav on bare category goals is said in words, not hidden in a table."""
    sums = [summ("capnav", "label", [1.0, 1.0, 1.0, 0.5], 0.9),
            summ("category-only", "label", [1.0, 1.0, 1.0, 0.5], 0.9),
            summ("vlmaps", "label", [0.5, 0.0, 0.0, 0.0], 0.4), summ("cow", "label", [1.0, 1.0, 1.0, 1.0], 0.95)]
    md = render(sums, {"seed": 0, "scenes": 1, "scene_seeds": [0], "episodes_per_scene": 2})
    line = next(ln for ln in md.splitlines() if ln.startswith("- paper rule:"))
    assert "capnav 90.0%" in line and "tied by category-only" in line
    assert "above it: cow (95.0)" in line and "below it: 1 of 3" in line


def test_a_phrasing_run_shows_only_its_own_table_without_chains() -> None:
    """A run of hand-written instructions has one subgoal per episode: no empty label or description
    tables, no in-a-row columns."""
    sums = [summ("capnav", "phrasing", [0.9, 0.0, 0.0, 0.0], 0.9),
            summ("category-only", "phrasing", [0.5, 0.0, 0.0, 0.0], 0.5)]
    md = render(sums, {"seed": 0, "scenes": 1, "scene_seeds": [61], "episodes_per_scene": 9,
                       "instructions": "dev.jsonl"})
    assert "## Table 1" not in md and "## Table 2" not in md and "## Description protocol" not in md
    assert "| Method | Success [95% CI] | SPL | Strict success | Strict, in its room |" in md
    assert "episodes from `dev.jsonl`" in md and "episodes per apartment" not in md
    assert next(ln for ln in md.splitlines() if ln.startswith("| capnav |")).startswith("| capnav | 90.0 | 50.0 |")


def test_the_console_line_of_a_phrasing_run_has_no_chains() -> None:
    from capnav.cli.eval import summary_line

    assert "in a row" not in summary_line(summ("capnav", "phrasing", [0.9, 0.0, 0.0, 0.0], 0.9))
    assert "in a row 100 / 50 / 50 / 25, indep. 62.5%" in summary_line(summ("capnav", "label",
                                                                            [1.0, 0.5, 0.5, 0.25], 0.625))


def test_the_interval_and_the_room_rule_stand_beside_independent_success() -> None:
    """A reader sees the spread (bootstrap interval) and the strict rule with the room next to the
    paper's figure; a run without room truth says "–" rather than 0."""
    with_room = summ("capnav", "description", [0.5, 0.5, 0.0, 0.0], 0.5)
    with_room.independent_ci = [0.25, 0.75]
    with_room.independent_strict, with_room.independent_room = 0.5, 0.375
    no_room = summ("vlmaps", "description", [0.5, 0.0, 0.0, 0.0], 0.4)
    md = render([with_room, no_room], {"seed": 0, "scenes": 1, "scene_seeds": [0], "episodes_per_scene": 2})
    rows: dict[str, str] = {}
    for ln in md.splitlines():  # the first row of each method: the description table, before the details
        if ln.startswith(("| capnav |", "| vlmaps |")):
            rows.setdefault(ln.split(" | ")[0], ln)
    assert "| 50.0 [25.0-75.0] |" in rows["| capnav"] and rows["| capnav"].endswith("| 50.0 | 37.5 |")
    assert rows["| vlmaps"].endswith("| – | – |") and "| 40.0 |" in rows["| vlmaps"]
    assert "Strict, in its room" in md
