"""A tiny name -> factory registry so backends are chosen by name in a config."""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import Any, Generic, TypeVar

from capnav.core.errors import InputError

T = TypeVar("T")


class Registry(Generic[T]):
    """Maps backend names to factories. ``create(name, **kw)`` builds one.

    Each pluggable stage (detector, encoder, captioner, embedder, verifier, planner, method)
    owns one registry; modules register their backends with ``@REGISTRY.register("name")``.
    """

    def __init__(self, kind: str) -> None:
        self.kind = kind
        self._factories: dict[str, Callable[..., T]] = {}

    def register(self, name: str) -> Callable[[Callable[..., T]], Callable[..., T]]:
        def deco(factory: Callable[..., T]) -> Callable[..., T]:
            if name in self._factories:
                raise ValueError(f"{self.kind} backend {name!r} registered twice")
            self._factories[name] = factory
            return factory

        return deco

    def names(self) -> list[str]:
        return sorted(self._factories)

    def _factory(self, name: str) -> Callable[..., T]:
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
        return name in self._factories
