"""The text-embedder interface (paper eq. 14-15): texts in, L2-normalised float32 vectors out.

Backends register in ``EMBEDDERS`` and only implement ``_encode``; this base class validates
input, normalises, and caches vectors of repeated texts (captions and instructions repeat a lot).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections import OrderedDict
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError, ModelError
from capnav.core.registry import Registry


class TextEmbedder(ABC):
    """Base class of every text embedder. ``model_id`` names the vector space; vectors from
    different ``model_id`` values must never be compared (the map stores it with each embedding)."""

    model_id: str
    dim: int

    def __init__(self, cache_size: int = 8192) -> None:
        self._cache: OrderedDict[str, NDArray[np.float32]] = OrderedDict()
        self._cache_size = int(cache_size)

    @abstractmethod
    def _encode(self, texts: list[str]) -> NDArray[np.floating[Any]]:
        """Raw (not necessarily normalised) vectors (len(texts), dim) for non-empty texts."""

    def embed(self, texts: Sequence[str]) -> NDArray[np.float32]:
        """Embed ``texts``; returns (n, dim) float32 rows with unit L2 norm (eq. 14/15)."""
        if isinstance(texts, str):
            raise InputError("embed() takes a list of strings, not a single string")
        texts = list(texts)
        for t in texts:
            if not isinstance(t, str):
                raise InputError(f"embed() needs strings, got {type(t).__name__}")
        out = np.empty((len(texts), self.dim), dtype=np.float32)
        missing: list[str] = []
        for t in texts:
            if t not in self._cache and t not in missing:
                missing.append(t)
        if missing:
            vecs = np.asarray(self._encode(missing), dtype=np.float32)
            if vecs.shape != (len(missing), self.dim):
                raise ModelError(f"{self.model_id} returned shape {vecs.shape}, expected ({len(missing)}, {self.dim})")
            if not np.all(np.isfinite(vecs)):
                raise ModelError(f"{self.model_id} returned non-finite embeddings")
            norms = np.linalg.norm(vecs, axis=1, keepdims=True)
            vecs = vecs / np.maximum(norms, 1e-12)
            for t, v in zip(missing, vecs, strict=True):
                self._put(t, v)
        for i, t in enumerate(texts):
            out[i] = self._cache[t]
            self._cache.move_to_end(t)
        return out

    def embed_one(self, text: str) -> NDArray[np.float32]:
        return self.embed([text])[0]

    def _put(self, text: str, vec: NDArray[np.float32]) -> None:
        vec = vec.copy()
        vec.setflags(write=False)
        self._cache[text] = vec
        while len(self._cache) > self._cache_size:
            self._cache.popitem(last=False)

    def __repr__(self) -> str:
        return f"{type(self).__name__}(model_id={self.model_id!r}, dim={self.dim})"


EMBEDDERS: Registry[TextEmbedder] = Registry("embedder", providers={
    **dict.fromkeys(["minilm", "onnx"], "capnav.language.onnx_embedder"),
    **dict.fromkeys(["sentence-transformers", "bge-m3", "flag"], "capnav.language.st_embedder")})


def create_embedder(name: str = "minilm", **kwargs: Any) -> TextEmbedder:
    """Build a text embedder by backend name: ``minilm`` (offline default), ``onnx`` (any local
    MiniLM-style folder), ``sentence-transformers`` (BGE-M3 or any ST folder), ``flag`` (BGE-M3
    via FlagEmbedding)."""
    return EMBEDDERS.create(name, **kwargs)
