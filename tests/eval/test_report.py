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
