"""The offline dense feature encoder: each pixel gets the text embedding of what it shows.

It stands in for LSeg (paper section 3.1): pixels inside a detection's mask get the embedding of
the detected label (so the detector's misses, confusions and mask noise carry over), other pixels
get the embedding of a "stuff" label decided from observed geometry (``floor`` below
``floor_height`` in the world, ``wall`` otherwise). Because features live in the text embedder's
space, a text query embedded by the same model can be compared with every pixel / voxel, which is
what a VLMaps-style dense query needs. The map is predicted on a grid with ``stride`` (LSeg also
predicts at reduced resolution); pixel (u, v) reads cell (v // stride, u // stride).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError
from capnav.core.frame import Frame
from capnav.perception.base import ENCODERS, DenseFeatureEncoder, Detection, TextEmbedderLike


class LabelEmbeddingEncoder(DenseFeatureEncoder):
    """Per-pixel text embedding of the detected label (offline LSeg stand-in)."""

    def __init__(self, embedder: TextEmbedderLike | None = None, stride: int = 4,
                 floor_label: str = "floor", wall_label: str = "wall", floor_height: float = 0.08) -> None:
        if stride < 1:
            raise InputError(f"encoder stride must be >= 1, got {stride}")
        if embedder is None:
            from capnav.language import create_embedder

            embedder = create_embedder("minilm")
        if not isinstance(embedder, TextEmbedderLike):
            raise InputError(f"embedder must provide model_id, dim and embed(); got {type(embedder).__name__}")
        self.embedder = embedder
        self.stride = int(stride)
        self.floor_label, self.wall_label = floor_label, wall_label
        self.floor_height = float(floor_height)
        self.dim = int(embedder.dim)
        self.text_space = embedder.model_id
        self.id = f"label-embedding:{embedder.model_id}:stride={self.stride}"
        self._labels: list[str] = []
        self._index: dict[str, int] = {}
        self._table = np.zeros((0, self.dim), dtype=np.float32)
        self._lookup([floor_label, wall_label])

    def _lookup(self, labels: Sequence[str]) -> NDArray[np.intp]:
        new = [lab for lab in dict.fromkeys(labels) if lab not in self._index]
        if new:
            vecs = np.asarray(self.embedder.embed(new), dtype=np.float32)
            for lab in new:
                self._index[lab] = len(self._labels)
                self._labels.append(lab)
            self._table = np.concatenate([self._table, vecs], axis=0)
        return np.array([self._index[lab] for lab in labels], dtype=np.intp)

    def grid_shape(self, height: int, width: int) -> tuple[int, int]:
        return (-(-height // self.stride), -(-width // self.stride))

    def label_grid(self, frame: Frame, detections: Sequence[Detection]) -> NDArray[np.intp]:
        """(H', W') indices into the label table: stuff by geometry, then detections by score."""
        h, w = frame.shape
        hh, ww = self.grid_shape(h, w)
        vs = np.minimum(np.arange(hh) * self.stride + self.stride // 2, h - 1)
        us = np.minimum(np.arange(ww) * self.stride + self.stride // 2, w - 1)
        z = np.asarray(frame.depth, dtype=np.float64)[np.ix_(vs, us)]
        K = frame.K
        T = np.asarray(frame.T_wc, dtype=np.float64)
        stuff = self._lookup([self.floor_label, self.wall_label])
        with np.errstate(invalid="ignore"):  # invalid depth (0, NaN, inf) is "wall": it never reaches a voxel
            xc = (us[None, :] - K.cx) / K.fx * z
            yc = (vs[:, None] - K.cy) / K.fy * z
            zw = T[2, 0] * xc + T[2, 1] * yc + T[2, 2] * z + T[2, 3]
            grid = np.where(zw < self.floor_height, stuff[0], stuff[1]).astype(np.intp)
        if detections:
            ids = self._lookup([d.label for d in detections])
            for k in np.argsort([d.score for d in detections], kind="stable"):
                m = detections[k].mask[np.ix_(vs, us)]
                grid[m] = ids[k]
        return grid

    def encode_indexed(self, frame: Frame, detections: Sequence[Detection]
                       ) -> tuple[NDArray[np.int64], NDArray[np.float32]]:
        grid = self.label_grid(frame, detections).astype(np.int64)
        return grid, self._table

    def encode(self, frame: Frame, detections: Sequence[Detection]) -> NDArray[np.float32]:
        grid = self.label_grid(frame, detections)  # may grow the table: index it afterwards
        return self._table[grid]


@ENCODERS.register("label-embedding")
def _make_label_encoder(embedder: TextEmbedderLike | None = None, stride: int = 4, **kw: float | str
                        ) -> LabelEmbeddingEncoder:
    return LabelEmbeddingEncoder(embedder=embedder, stride=stride, **kw)  # type: ignore[arg-type]
