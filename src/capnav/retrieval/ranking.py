"""Cosine ranking (eq. 16), top-K and maximal marginal relevance over caption embeddings."""

from __future__ import annotations

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
