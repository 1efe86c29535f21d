"""A tiny name -> factory registry so backends are chosen by name in a config."""

from __future__ import annotations

import importlib
import inspect
from collections.abc import Callable
from typing import Any, Generic, TypeVar

from capnav.core.errors import InputError

T = TypeVar("T")


class Registry(Generic[T]):
    """Maps backend names to factories. ``create(name, **kw)`` builds one.

    Each pluggable stage (detector, encoder, captioner, embedder, verifier, planner, method)
    owns one registry; modules register their backends with ``@REGISTRY.register("name")``.
    ``providers`` names the module that registers a backend, imported when that backend is first
    looked up: a process pays only for the backends it uses (the Gemini client, PyTorch for
    sentence-transformers), and a package need not import every backend to fill its registry.
    """

    def __init__(self, kind: str, providers: dict[str, str] | None = None) -> None:
        self.kind = kind
        self._factories: dict[str, Callable[..., T]] = {}
        self._providers = dict(providers or {})

    def register(self, name: str) -> Callable[[Callable[..., T]], Callable[..., T]]:
        def deco(factory: Callable[..., T]) -> Callable[..., T]:
            if name in self._factories:
                raise ValueError(f"{self.kind} backend {name!r} registered twice")
            self._factories[name] = factory
            return factory

        return deco

    def names(self) -> list[str]:
        return sorted({*self._factories, *self._providers})

    def _factory(self, name: str) -> Callable[..., T]:
        if name not in self._factories and name in self._providers:
            importlib.import_module(self._providers[name])  # registers ``name`` as it loads
        try:
            return self._factories[name]
        except KeyError:
            raise InputError(
                f"unknown {self.kind} backend {name!r}; available: {', '.join(self.names()) or 'none'}"
            ) from None

    def required(self, name: str) -> list[str]:
        """The settings backend ``name`` cannot do without (e.g. ``path`` of a local model folder)."""
        sig = inspect.signature(self._factory(name))
        return [p.name for p in sig.parameters.values() if p.default is inspect.Parameter.empty
                and p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]

    def create(self, name: str, **kwargs: Any) -> T:
        factory = self._factory(name)
        missing = [k for k in self.required(name) if k not in kwargs]
        if missing:  # say so, instead of a TypeError from deep inside the backend
            what = " and ".join("a local model folder (path)" if k == "path" else k for k in missing)
            raise InputError(f"{self.kind} backend {name!r} needs {what}")
        return factory(**kwargs)

    def __contains__(self, name: object) -> bool:
        return name in self._factories or name in self._providers
