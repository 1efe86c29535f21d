"""Modules imported on first attribute access (``importlib.util.LazyLoader``).

Why: a one-shot command pays for every module it imports. Reading a map file constructs a
``VoxelMap`` (even an empty one for ``capnav query``) whose numba kernels cost about 0.5 s to
import; deferred, they load only when a voxel is actually hashed or fused."""

from __future__ import annotations

import importlib
import importlib.util
import sys
from collections.abc import Callable
from types import ModuleType
from typing import Any


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


def lazy_exports(package: str, sources: dict[str, str]) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """PEP 562 ``__getattr__`` and ``__dir__`` for a package whose public names (``sources``: name
    -> submodule) are imported on first use, so that importing one submodule of the package does
    not import all of them."""
    module = sys.modules[package]

    def __getattr__(name: str) -> Any:
        sub = sources.get(name)
        if sub is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f"{package}.{sub}"), name)
        setattr(module, name, value)
        return value

    def __dir__() -> list[str]:
        return sorted({*vars(module), *sources})

    return __getattr__, __dir__


__all__ = ["lazy_exports", "lazy_module"]
