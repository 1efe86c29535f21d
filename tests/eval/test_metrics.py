"""Metrics against hand-computed episodes (in-a-row counting, independent success, SPL)."""

from __future__ import annotations

import math

import pytest

from capnav.core.errors import InputError
from capnav.eval.metrics import SubgoalRecord, chains_of, in_a_row, spl, summarize, summarize_all


def rec(ep: str, i: int, ok: bool, *, method: str = "m", protocol: str = "label", path: float = 4.0,
        shortest: float = 2.0, qt: float = 0.01, correct: bool | None = True) -> SubgoalRecord:
    return SubgoalRecord(method=method, protocol=protocol, scene_seed=0, episode_id=ep, index=i, text="sofa",
                         category="sofa", target_ids=[1], kind="category", success=ok,
                         distance_to_goal=0.5 if ok else 3.0, path_length=path, shortest_path=shortest,
                         start_xy=(0.0, 0.0), stop_xy=(1.0, 1.0), found=True, retrieval_correct=correct,
                         query_time_s=qt, steps=10)


def test_in_a_row_hand_computed() -> None:
    chains = [[True, True, False, True],   # 1, 2 in a row
              [False, True, True, True],   # 0
              [True, True, True, True],    # 4
              [True, False, True, True]]   # 1
    # k=1: episodes 0, 2, 3 -> 3/4; k=2: 0, 2 -> 2/4; k=3: 2 -> 1/4; k=4: 2 -> 1/4
    assert in_a_row(chains) == [0.75, 0.5, 0.25, 0.25]
    # a success after a failure never counts towards in-a-row
    assert in_a_row([[False, True, True, True]]) == [0.0, 0.0, 0.0, 0.0]
    # an episode shorter than k cannot have k in a row
    assert in_a_row([[True, True]]) == [1.0, 1.0, 0.0, 0.0]


def test_spl_hand_computed() -> None:
    assert spl(True, 2.0, 4.0) == pytest.approx(0.5)
    assert spl(True, 2.0, 1.5) == pytest.approx(1.0)  # shorter than geodesic (region entered early): capped
    assert spl(False, 2.0, 2.0) == 0.0
    assert spl(True, math.inf, 3.0) == 0.0
    assert spl(True, 0.0, 3.0) == 1.0


def test_summary_hand_computed() -> None:
    oks = {"a": [True, True, False, True], "b": [False, True, True, True]}
    records = [rec(ep, i, ok, path=4.0 if i % 2 else 2.0, qt=0.01 * (i + 1), correct=ok)
               for ep, chain in oks.items() for i, ok in enumerate(chain)]
    s = summarize(records[::-1])  # order must not matter
    assert s.episodes == 2 and s.subgoals == 8
    assert s.in_a_row == [0.5, 0.5, 0.0, 0.0]
    assert s.independent == pytest.approx(6 / 8)
    # successes: a0 (2 m, spl 1), a1 (4 m, 0.5), a3 (4 m, 0.5), b1 (0.5), b2 (2 m, 1), b3 (0.5)
    assert s.spl == pytest.approx((1 + 0.5 + 0.5 + 0.5 + 1 + 0.5) / 8)
    assert s.path_length == pytest.approx(3.0)
    assert s.retrieval_top1 == pytest.approx(6 / 8)
    assert s.query_time_mean_s == pytest.approx(0.025)


def test_record_roundtrip_with_inf() -> None:
    r = rec("a", 0, False, shortest=math.inf)
    d = r.to_dict()
    assert d["shortest_path"] is None and d["spl"] == 0.0
    back = SubgoalRecord.from_dict(d)
    assert math.isinf(back.shortest_path) and back.stop_xy == (1.0, 1.0)


def test_bad_records_are_clear_errors() -> None:
    with pytest.raises(InputError, match="missing subgoals"):
        chains_of([rec("a", 0, True), rec("a", 2, True)])
    with pytest.raises(InputError, match="two records"):
        chains_of([rec("a", 0, True), rec("a", 0, False)])
    with pytest.raises(InputError, match="one method"):
        summarize([rec("a", 0, True, method="x"), rec("b", 0, True, method="y")])
    with pytest.raises(InputError):
        summarize([])


def test_summarize_all_groups() -> None:
    rs = [rec("a", 0, True, method="x"), rec("a", 0, False, method="y"), rec("a", 0, True, method="y",
                                                                               protocol="description")]
    out = {(s.method, s.protocol): s.independent for s in summarize_all(rs)}
    assert out == {("x", "label"): 1.0, ("y", "label"): 0.0, ("y", "description"): 1.0}


def test_bootstrap_interval_resamples_episodes_and_brackets_the_rate() -> None:
    from capnav.eval.metrics import bootstrap_ci

    chains = [[True] * 4] * 15 + [[True, False, False, False]] * 5  # 65 of 80 subgoals
    lo, hi = bootstrap_ci(chains)
    assert lo < 65 / 80 < hi and hi - lo > 0.05
    assert bootstrap_ci(chains) == [lo, hi]  # seeded
    assert bootstrap_ci([[True] * 4] * 10) == [1.0, 1.0]
    # more episodes of the same mix: a narrower interval
    lo2, hi2 = bootstrap_ci(chains * 9)
    assert hi2 - lo2 < hi - lo
