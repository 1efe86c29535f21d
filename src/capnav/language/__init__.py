"""Language stage: view selection, captioners, text embedders and their caches (paper 3.3)."""

from capnav.language import onnx_embedder as _onnx_embedder  # noqa: F401  (registers backends)
from capnav.language import st_embedder as _st_embedder  # noqa: F401
from capnav.language.embedder import EMBEDDERS, TextEmbedder, create_embedder

__all__ = ["EMBEDDERS", "TextEmbedder", "create_embedder"]
