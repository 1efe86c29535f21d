"""A seeded depth-noise model of a consumer structured-light RGB-D sensor (off by default)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from capnav.sim.config import DepthNoiseConfig


def apply_depth_noise(depth: NDArray[np.float32], cfg: DepthNoiseConfig, index: int) -> NDArray[np.float32]:
    """Noisy copy of ``depth``; deterministic for (``cfg.seed``, frame ``index``). Invalid = 0."""
    rng = np.random.default_rng([cfg.seed, index])
    z = depth.astype(np.float64)
    valid = np.isfinite(z) & (z > 0)
    # Depth discontinuities: structured-light sensors lose pixels along object silhouettes.
    zz = np.where(valid, z, 0.0)
    jump = np.zeros(z.shape, dtype=bool)
    dx = np.abs(np.diff(zz, axis=1)) > cfg.edge_threshold
    dy = np.abs(np.diff(zz, axis=0)) > cfg.edge_threshold
    jump[:, 1:] |= dx
    jump[:, :-1] |= dx
    jump[1:, :] |= dy
    jump[:-1, :] |= dy
    u = rng.random(z.shape)
    drop = (jump & (u < cfg.edge_dropout)) | (rng.random(z.shape) < cfg.dropout)
    sigma = cfg.sigma0 + cfg.sigma2 * (z - 0.4) ** 2
    noisy = z + rng.standard_normal(z.shape) * sigma
    if cfg.quantum > 0:
        noisy = np.round(noisy / cfg.quantum) * cfg.quantum
    keep = valid & ~drop & (z >= cfg.min_range) & (z <= cfg.max_range)
    return np.where(keep, noisy, 0.0).astype(np.float32)
