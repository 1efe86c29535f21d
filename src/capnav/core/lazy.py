"""Modules imported on first attribute access (``importlib.util.LazyLoader``).

Why: a one-shot command pays for every module it imports. Reading a map file constructs a
``VoxelMap`` (even an empty one for ``capnav query``) whose numba kernels cost about 0.5 s to
import; deferred, they load only when a voxel is actually hashed or fused."""

from __future__ import annotations

import importlib.util
import sys
from types import ModuleType


def lazy_module(name: str) -> ModuleType:
    """``name`` as a module object that executes on first attribute access (at once if already
    imported)."""
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.find_spec(name)
    if spec is None or spec.loader is None:
        raise ImportError(f"no module named {name!r}")
    loader = importlib.util.LazyLoader(spec.loader)
    spec.loader = loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    loader.exec_module(module)
    return module


__all__ = ["lazy_module"]
