"""The purpose gloss index is kept per embedder for as long as the embedder lives, not for the
process: a table keyed by the embedder's id kept every embedder ever used (with its ONNX session),
and a test session or a server opening maps one after another grew by ~130 MB per embedder."""

from __future__ import annotations

import gc
import weakref
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from capnav.language.purpose import gloss_index, match_purpose


class _Tiny:
    """A stand-in embedder: unit vectors from the text's hash (cheap, deterministic)."""

    model_id = "test-tiny-8"
    dim = 8

    def embed(self, texts: Sequence[str]) -> NDArray[np.float32]:
        out = np.stack([np.random.default_rng(abs(hash(t)) % (2**32)).normal(size=self.dim) for t in texts])
        return (out / np.linalg.norm(out, axis=1, keepdims=True)).astype(np.float32)

    def embed_one(self, text: str) -> NDArray[np.float32]:
        return self.embed([text])[0]


def test_an_embedder_and_its_index_go_together() -> None:
    e = _Tiny()
    idx = gloss_index(e)  # type: ignore[arg-type]
    assert gloss_index(e) is idx  # reused while the embedder lives  # type: ignore[arg-type]
    assert match_purpose("sleep", e).scores  # type: ignore[arg-type]
    alive = weakref.ref(e)
    del e, idx
    gc.collect()
    assert alive() is None
