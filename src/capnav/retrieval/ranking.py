"""Cosine ranking (eq. 16), top-K and maximal marginal relevance over caption embeddings, and the
order the constraints' keys give (``Ranking``)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

F32 = NDArray[np.float32]


def cosine_scores(E: F32, q: F32) -> F32:
    """s_j = e_q^T e_j for unit rows of ``E`` (n, d) and a unit query ``q`` (d,)."""
    return np.asarray(E @ q, dtype=np.float32)


def top_k(scores: NDArray[np.floating], k: int, among: NDArray[np.intp] | None = None) -> NDArray[np.intp]:
    """Indices of the ``k`` best scores (optionally among a subset), best first, ties by index."""
    idx = np.arange(len(scores)) if among is None else np.asarray(among, dtype=np.intp)
    if len(idx) == 0:
        return idx
    k = min(k, len(idx))
    s = scores[idx]
    part = np.argpartition(-s, k - 1)[:k] if k < len(idx) else np.arange(len(idx))
    order = part[np.lexsort((idx[part], -s[part]))]
    return idx[order]


def mmr(E: F32, scores: NDArray[np.floating], candidates: NDArray[np.intp], lam: float) -> NDArray[np.intp]:
    """Reorder ``candidates`` by maximal marginal relevance:
    argmax_j  lam * s_j - (1 - lam) * max_{i chosen} cos(e_j, e_i)."""
    cand = list(np.asarray(candidates, dtype=np.intp))
    if len(cand) <= 2 or lam >= 1.0:
        return np.asarray(cand, dtype=np.intp)
    sub = E[cand]
    sim = sub @ sub.T
    rel = np.asarray(scores, dtype=np.float64)[cand]
    chosen: list[int] = [0]
    max_sim = sim[0].astype(np.float64).copy()
    left = np.ones(len(cand), dtype=bool)
    left[0] = False
    while left.any():
        val = lam * rel - (1.0 - lam) * max_sim
        val[~left] = -np.inf
        j = int(np.argmax(val))
        chosen.append(j)
        left[j] = False
        max_sim = np.maximum(max_sim, sim[j])
    return np.asarray([cand[j] for j in chosen], dtype=np.intp)


@dataclass
class Ranking:
    """The retrieval order with what decided it."""

    order: NDArray[np.intp]  # candidate indices, best first
    groups: NDArray[np.int64]  # per position: predicate group (ties on the predicate share one)
    mode: str  # "semantic", "predicate" or "closest"
    predicate: str | None
    weights: NDArray[np.float64]  # per object: category weight (1 named, < 1 alternative)
    terms: dict[int, dict[str, float]]  # per candidate: the predicate's values (distance, volume, ...)
    refusal: str | None = None  # a reason to answer "not found" before verification
    refused_by: str | None = None  # the kind of constraint that refused
    unmet: dict[int, str] = field(default_factory=dict)  # per candidate: the relation it does not meet
    out_of_reach: dict[int, float] = field(default_factory=dict)  # per candidate: its gap beyond the reach
    reach: float | None = None  # that reach (m): farther than it, a candidate does not meet the relation


def semantic_order(E: F32, s: NDArray[np.float32], pool: NDArray[np.intp], weights: NDArray[np.float64],
                   k: int, lam: float | None) -> tuple[NDArray[np.intp], NDArray[np.int64]]:
    """Per category tier (named category, then alternatives), the ``k`` most similar with MMR
    (``lam`` None: without); the group of each is its tier."""
    tiers = sorted(set(weights[pool].tolist()), reverse=True)
    parts = []
    for w in tiers:
        tier = pool[weights[pool] == w]
        sub = top_k(s, k, tier[np.lexsort((tier, -s[tier]))])
        parts.append(mmr(E, s, sub, lam) if lam is not None else sub)
    order = np.concatenate(parts) if parts else pool
    tier_of = {int(i): t for t, w in enumerate(tiers) for i in pool[weights[pool] == w]}
    return order, np.array([tier_of[int(i)] for i in order], dtype=np.int64)


def keyed_order(s: NDArray[np.float32], pool: NDArray[np.intp], group_keys: list[NDArray[np.float64]],
                order_keys: list[NDArray[np.float64]]) -> tuple[NDArray[np.intp], NDArray[np.int64]]:
    """Lexicographic: first group key most significant; then order keys, similarity, index. A
    group is a run of candidates equal on every group key."""
    keys = [pool.astype(np.float64), -s[pool].astype(np.float64), *reversed(order_keys), *reversed(group_keys)]
    perm = np.lexsort(keys)
    order = pool[perm]
    gk = np.stack([k[perm] for k in group_keys], axis=1)
    change = np.r_[True, np.any(gk[1:] != gk[:-1], axis=1)] if len(gk) else np.zeros(0, bool)
    return order, np.asarray(np.cumsum(change) - 1, dtype=np.int64)
