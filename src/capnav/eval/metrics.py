"""Benchmark metrics, computed from per-subgoal records.

- In-a-row success for k = 1..4 (VLMaps' counting, the paper's Table 1): the fraction of episodes
  whose first k subgoals all succeeded. k = 4 is the paper's Table 2 "Success Rate".
- Independent subgoal success: over all subgoals, regardless of the chain.
- SPL (Anderson et al. 2018): S * l / max(p, l) with l the geodesic distance from the subgoal's
  start to the nearest point of its success region and p the path the agent drove.
- Retrieval top-1: the method's chosen target lies at the right instance (description protocol).
- Time per query: wall time of the method's decision, motion excluded.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from capnav.core.errors import InputError

MAX_CHAIN = 4


@dataclass
class SubgoalRecord:
    """One scored subgoal: what the method did and how the harness judged it."""

    method: str
    protocol: str
    scene_seed: int
    episode_id: str
    index: int  # position in the episode, 0-based
    text: str
    category: str
    target_ids: list[int]
    kind: str
    success: bool
    distance_to_goal: float  # stop point to nearest goal footprint (m)
    path_length: float  # driven in this subgoal (m)
    shortest_path: float  # geodesic start -> success region (m); inf if unreachable
    start_xy: tuple[float, float]
    stop_xy: tuple[float, float]
    found: bool  # the method claimed a goal
    retrieval_correct: bool | None  # the chosen target is at a goal instance (None: no target chosen)
    query_time_s: float
    steps: int
    reason: str = ""
    target_xy: tuple[float, float] | None = None
    chosen_object: int | None = None
    explanation: str = ""
    trajectory: list[tuple[float, float]] = field(default_factory=list)
    error: str = ""  # non-empty when the method crashed on this subgoal (scored as a failure)
    #: Strict rule: within 1 m of a goal instance AND in sight of it (no wall or tall object between);
    #: None for records made without the scene's sight grid.
    success_strict: bool | None = None
    #: The strict rule and the stop point in the goal instance's room; None without room truth.
    success_room: bool | None = None
    #: Geodesic start -> the nearest viewpoint (a cell within the radius with the goal in sight);
    #: set where a budget is judged against it (the change track's searches), else None.
    view_path: float | None = None

    @property
    def spl(self) -> float:
        return spl(self.success, self.shortest_path, self.path_length)

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["spl"] = self.spl
        for k in ("shortest_path", "distance_to_goal"):
            if not math.isfinite(d[k]):
                d[k] = None  # JSON has no inf
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> SubgoalRecord:
        d = dict(d)
        d.pop("spl", None)
        for k in ("shortest_path", "distance_to_goal"):
            if d.get(k) is None:
                d[k] = float("inf")
        for k in ("start_xy", "stop_xy", "target_xy"):
            if d.get(k) is not None:
                d[k] = (float(d[k][0]), float(d[k][1]))
        d["trajectory"] = [(float(x), float(y)) for x, y in d.get("trajectory", [])]
        return cls(**d)


def spl(success: bool, shortest: float, path_length: float) -> float:
    """Success weighted by path length for one subgoal. An unreachable goal (l = inf) scores 0,
    and a start already inside the region (l = 0) scores 1 on success whatever the detour."""
    if not success or not math.isfinite(shortest):
        return 0.0
    if shortest <= 0.0:
        return 1.0
    return float(shortest / max(path_length, shortest))


@dataclass
class Summary:
    """Aggregate numbers for one (method, protocol)."""

    method: str
    protocol: str
    episodes: int
    subgoals: int
    in_a_row: list[float]  # k = 1..4, fractions
    independent: float
    spl: float
    path_length: float  # mean per subgoal (m)
    retrieval_top1: float | None
    query_time_mean_s: float
    query_time_p50_s: float
    found_rate: float
    crashes: int = 0  # subgoals on which the method raised an unexpected exception
    #: The same two figures under the strict rule (stopped within 1 m AND in sight); None without it.
    in_a_row_strict: list[float] | None = None
    independent_strict: float | None = None
    #: Bootstrap 95% interval of ``independent`` (episodes resampled: subgoals of one episode share a start).
    independent_ci: list[float] | None = None
    #: Strict and in the object's room (the stop point in the room the object stands in).
    independent_room: float | None = None

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def in_a_row(chains: Sequence[Sequence[bool]], max_k: int = MAX_CHAIN) -> list[float]:
    """Fraction of episodes whose first k subgoals all succeeded, for k = 1..max_k.

    An episode shorter than k counts as a failure at k (it cannot have k in a row)."""
    if not chains:
        return [0.0] * max_k
    out = []
    for k in range(1, max_k + 1):
        ok = sum(1 for c in chains if len(c) >= k and all(c[:k]))
        out.append(ok / len(chains))
    return out


def chains_of(records: Iterable[SubgoalRecord], strict: bool = False) -> list[list[bool]]:
    """Per-episode success chains in subgoal order (records may come in any order)."""
    by_ep: dict[tuple[int, str], dict[int, bool]] = defaultdict(dict)
    for r in records:
        key = (r.scene_seed, r.episode_id)
        if r.index in by_ep[key]:
            raise InputError(f"episode {r.episode_id} has two records for subgoal {r.index}")
        by_ep[key][r.index] = bool(r.success_strict) if strict else r.success
    chains = []
    for key in sorted(by_ep):
        d = by_ep[key]
        if sorted(d) != list(range(len(d))):
            raise InputError(f"episode {key[1]} is missing subgoals: has indices {sorted(d)}")
        chains.append([d[i] for i in range(len(d))])
    return chains


def bootstrap_ci(groups: Sequence[Sequence[bool]], resamples: int = 2000, level: float = 0.95, seed: int = 0
                 ) -> list[float]:
    """Percentile bootstrap interval of the success rate over all items, resampling whole groups
    (episodes) with replacement; seeded, so a report is reproducible."""
    if not groups:
        return [0.0, 0.0]
    ok = np.array([sum(map(bool, g)) for g in groups], dtype=np.float64)
    n = np.array([len(g) for g in groups], dtype=np.float64)
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, len(groups), size=(resamples, len(groups)))
    rates = ok[idx].sum(axis=1) / np.maximum(n[idx].sum(axis=1), 1.0)
    a = (1.0 - level) / 2.0
    return [float(np.quantile(rates, a)), float(np.quantile(rates, 1.0 - a))]


def summarize(records: Sequence[SubgoalRecord]) -> Summary:
    """All metrics for the records of ONE (method, protocol)."""
    if not records:
        raise InputError("no records to summarize")
    methods = {r.method for r in records}
    protocols = {r.protocol for r in records}
    if len(methods) != 1 or len(protocols) != 1:
        raise InputError(f"summarize one method and protocol at a time, got {methods} x {protocols}")
    chains = chains_of(records)
    has_strict = all(r.success_strict is not None for r in records)
    judged = [r.retrieval_correct for r in records]
    times = np.array([r.query_time_s for r in records], dtype=np.float64)
    return Summary(
        method=records[0].method,
        protocol=records[0].protocol,
        episodes=len(chains),
        subgoals=len(records),
        in_a_row=in_a_row(chains),
        independent=float(np.mean([r.success for r in records])),
        spl=float(np.mean([r.spl for r in records])),
        path_length=float(np.mean([r.path_length for r in records])),
        # a method that chose nothing was not right: None counts as wrong
        retrieval_top1=float(np.mean([bool(j) for j in judged])),
        query_time_mean_s=float(times.mean()),
        query_time_p50_s=float(np.median(times)),
        found_rate=float(np.mean([r.found for r in records])),
        crashes=sum(1 for r in records if r.error),
        in_a_row_strict=in_a_row(chains_of(records, strict=True)) if has_strict else None,
        independent_strict=float(np.mean([bool(r.success_strict) for r in records])) if has_strict else None,
        independent_ci=bootstrap_ci(chains),
        independent_room=float(np.mean([bool(r.success_room) for r in records]))
        if all(r.success_room is not None for r in records) else None,
    )


def summarize_all(records: Iterable[SubgoalRecord]) -> list[Summary]:
    """One summary per (method, protocol), in first-seen order."""
    groups: dict[tuple[str, str], list[SubgoalRecord]] = {}
    for r in records:
        groups.setdefault((r.method, r.protocol), []).append(r)
    return [summarize(g) for g in groups.values()]
