"""BGE-M3 (the paper's encoder) or any sentence-transformers model, loaded from a local folder.

Nothing is downloaded: ``local_files_only=True`` is the default, so a missing folder or cache
entry is a clear ``ModelError`` instead of a network call. FlagEmbedding is supported as an
option for BGE-M3; it silently builds random sparse/ColBERT heads when ``sparse_linear.pt`` /
``colbert_linear.pt`` are missing, so this loader refuses such folders unless told otherwise.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import ModelError, pip_hint
from capnav.language.embedder import EMBEDDERS, TextEmbedder


class SentenceTransformerEmbedder(TextEmbedder):
    """Dense embeddings with ``sentence_transformers.SentenceTransformer`` on CPU."""

    def __init__(self, path: str | os.PathLike[str], local_files_only: bool = True, device: str = "cpu",
                 batch_size: int = 32, model_id: str | None = None, cache_size: int = 8192) -> None:
        super().__init__(cache_size=cache_size)
        try:
            from sentence_transformers import SentenceTransformer
        except ImportError:
            raise ModelError(f"sentence-transformers is not installed: {pip_hint('capnav[bge]')}") from None
        p = Path(path)
        if local_files_only and p.is_absolute() and not p.is_dir():
            raise ModelError(f"sentence-transformers folder not found: {p}")
        try:
            self._model = SentenceTransformer(str(path), device=device, local_files_only=local_files_only)
        except Exception as e:
            raise ModelError(f"cannot load sentence-transformers model {path}: {e}") from None
        dim = self._model.get_embedding_dimension()
        if dim is None:
            dim = int(self._model.encode(["probe"], convert_to_numpy=True).shape[1])
        self.dim = int(dim)
        self.batch_size = int(batch_size)
        self.model_id = model_id or f"sentence-transformers:{p.name if p.is_dir() else str(path)}"

    def _encode(self, texts: list[str]) -> NDArray[np.float32]:
        vecs = self._model.encode(texts, batch_size=self.batch_size, convert_to_numpy=True,
                                  normalize_embeddings=True, show_progress_bar=False)
        return np.asarray(vecs, dtype=np.float32)


class FlagEmbedder(TextEmbedder):
    """BGE-M3 dense vectors via FlagEmbedding's ``BGEM3FlagModel`` (optional extra ``flag``)."""

    def __init__(self, path: str | os.PathLike[str], allow_random_heads: bool = False, batch_size: int = 16,
                 model_id: str | None = None, cache_size: int = 8192) -> None:
        super().__init__(cache_size=cache_size)
        p = Path(path)
        if not p.is_dir():
            raise ModelError(f"BGE-M3 folder not found: {p}")
        missing = [f for f in ("sparse_linear.pt", "colbert_linear.pt") if not (p / f).is_file()]
        if missing and not allow_random_heads:
            raise ModelError(f"{p} lacks {', '.join(missing)}: FlagEmbedding would use randomly initialised "
                             "heads; use the 'sentence-transformers' backend or pass allow_random_heads=True")
        try:
            from FlagEmbedding import BGEM3FlagModel
        except ImportError:
            raise ModelError(f"FlagEmbedding is not installed: {pip_hint('capnav[flag]')}") from None
        try:
            self._model = BGEM3FlagModel(str(p), use_fp16=False, devices="cpu")
        except Exception as e:
            raise ModelError(f"cannot load BGE-M3 from {p}: {e}") from None
        self.batch_size = int(batch_size)
        self.dim = int(self._encode(["probe"]).shape[1])
        self.model_id = model_id or f"bge-m3-flag:{p.name}"

    def _encode(self, texts: list[str]) -> NDArray[np.float32]:
        out = self._model.encode(texts, batch_size=self.batch_size, return_dense=True)
        return np.asarray(out["dense_vecs"], dtype=np.float32)


@EMBEDDERS.register("sentence-transformers")
def sentence_transformers(path: str | os.PathLike[str], **kwargs: Any) -> SentenceTransformerEmbedder:
    return SentenceTransformerEmbedder(path, **kwargs)


@EMBEDDERS.register("bge-m3")
def bge_m3(path: str | os.PathLike[str], **kwargs: Any) -> SentenceTransformerEmbedder:
    """BGE-M3 (BAAI/bge-m3) from a local folder through sentence-transformers."""
    kwargs.setdefault("model_id", f"BAAI/bge-m3:{Path(path).name}")
    return SentenceTransformerEmbedder(path, **kwargs)


@EMBEDDERS.register("flag")
def flag(path: str | os.PathLike[str], **kwargs: Any) -> FlagEmbedder:
    return FlagEmbedder(path, **kwargs)
