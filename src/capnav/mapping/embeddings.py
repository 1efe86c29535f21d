"""A map's caption embeddings checked before anyone searches them.

Retrieval ranks objects by the cosine of unit vectors (eq. 16). A map written by other code, or
damaged in a way its checksums do not see, can hold all-zero vectors (every similarity 0, and no
warning) or vectors that are not unit length (similarities off their scale): such a map is
refused where it is loaded for asking (``capnav serve``, ``capnav query``), naming the objects.
"""

from __future__ import annotations

import numpy as np

from capnav.core.errors import InputError
from capnav.mapping.cmap import CapNavMap

#: How far a stored caption embedding's length may be from 1 (they are saved as float32 unit vectors).
UNIT_TOLERANCE = 1e-3


def check_embeddings(cmap: CapNavMap, where: str) -> None:
    """Refuse a map whose caption embeddings cannot be searched: all zero, or not unit length (a
    map written by other code, or damaged in a way its checksums do not see)."""
    bad_zero, bad_len = [], []
    for o in cmap.objects:
        if o.embedding is None:
            continue
        n = float(np.linalg.norm(np.asarray(o.embedding, dtype=np.float64)))
        if not np.isfinite(n) or n == 0.0:
            bad_zero.append(o.id)
        elif abs(n - 1.0) > UNIT_TOLERANCE:
            bad_len.append((o.id, n))
    if bad_zero:
        raise InputError(f"{where}: {len(bad_zero)} objects have all-zero caption embeddings (ids {bad_zero[:10]}); "
                         "every similarity would be 0: re-run `capnav caption` on this map")
    if bad_len:
        ids = [i for i, _ in bad_len[:10]]
        raise InputError(f"{where}: {len(bad_len)} caption embeddings are not unit vectors (ids {ids}, lengths "
                         f"{', '.join(f'{n:.3f}' for _, n in bad_len[:3])}); re-run `capnav caption` on this map")
