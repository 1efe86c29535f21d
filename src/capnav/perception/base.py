"""Perception interfaces (paper eq. 9 and the LSeg feature map of section 3.1).

A ``Detector`` turns a frame into instance detections (box, class id, label, score, mask: eq. 9
plus Detic's mask). A ``DenseFeatureEncoder`` turns a frame into a per-pixel feature map that a
text query can be compared with (the paper's LSeg ``Phi_t``). Backends are chosen by name through
the ``DETECTORS`` / ``ENCODERS`` registries so a config can swap the simulator detector for a real
model without touching the mapper.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import FrameError, InputError
from capnav.core.frame import Frame
from capnav.core.registry import Registry

Box = tuple[float, float, float, float]


@dataclass
class Detection:
    """One detection of eq. 9: ``box`` xyxy pixels, ``class_id`` (vocabulary id, 0 = unknown),
    ``label`` text, ``score`` in [0, 1] and the instance ``mask`` (H, W) bool; ``votes`` holds the
    labels of overlapping detections of the same thing merged into it (``mapping.frame_merge``).
    ``weak``: a low-score candidate (below the detector's score threshold, above its candidate
    floor; ``Detector.detect_candidates``): the mapper lets it become an object only when several
    frames' sightings agree (``TrackerConfig.weak_h_min``), and its label never outvotes a
    confident detection's."""

    box: Box
    class_id: int
    label: str
    score: float
    mask: NDArray[np.bool_]
    votes: dict[str, float] = field(default_factory=dict)  # label -> score of detections merged into this one
    weak: bool = False

    def label_votes(self) -> dict[str, float]:
        """Scores per label this detection stands for: its own, plus those merged into it."""
        return dict(self.votes) if self.votes else {self.label: float(self.score)}

    @property
    def area(self) -> int:
        return int(self.mask.sum())

    def truncated(self, width: int, height: int, margin: float = 1.0) -> bool:
        """True when the box touches the image border (the object is probably cut off)."""
        x0, y0, x1, y1 = self.box
        return x0 <= margin or y0 <= margin or x1 >= width - margin or y1 >= height - margin


def box_from_mask(mask: NDArray[np.bool_]) -> Box:
    """Tight xyxy box of a mask (x1, y1 exclusive so a single pixel has area 1)."""
    rows = np.flatnonzero(mask.any(axis=1))
    cols = np.flatnonzero(mask.any(axis=0))
    if rows.size == 0:
        return (0.0, 0.0, 0.0, 0.0)
    return (float(cols[0]), float(rows[0]), float(cols[-1] + 1), float(rows[-1] + 1))


def validate_detections(frame: Frame, detections: Sequence[Detection]) -> list[Detection]:
    """Check detector output against the frame; raise ``FrameError`` naming the frame."""
    h, w = frame.shape
    out: list[Detection] = []
    for k, d in enumerate(detections):
        if d.mask.shape != (h, w):
            raise FrameError(frame.index, f"detection {k} mask shape {d.mask.shape} != image ({h}, {w})")
        if d.mask.dtype != np.bool_:
            raise FrameError(frame.index, f"detection {k} mask must be bool, got {d.mask.dtype}")
        if len(d.box) != 4 or not all(np.isfinite(v) for v in d.box):
            raise FrameError(frame.index, f"detection {k} has a non-finite box {d.box}")
        if not (0.0 <= float(d.score) <= 1.0):
            raise FrameError(frame.index, f"detection {k} score {d.score} is outside [0, 1]")
        out.append(d)
    return out


class Detector(ABC):
    """Instance detector: ``detect(frame) -> list[Detection]``. ``id`` names backend + settings
    (stored in the map's metadata so a map says how it was made)."""

    id: str = "detector"
    #: True for detectors that read the simulator's truth images (``Frame.gt_instance``), which a
    #: real recording does not have: mapping such a dataset with one is refused before any frame.
    needs_truth: bool = False
    #: The labels it can output (a closed vocabulary, recorded in the map so that a request for
    #: anything else is answered "the detector cannot see one", not "there is none"); None when
    #: any category may come out (the simulator's truth, an open vocabulary not recorded).
    labels: frozenset[str] | None = None

    @abstractmethod
    def detect(self, frame: Frame) -> list[Detection]:
        """Detections of one frame (possibly empty)."""

    def detect_candidates(self, frame: Frame) -> list[Detection]:
        """``detect`` plus low-score candidates marked ``weak`` (for a multi-frame mapper, which
        confirms them only by several sightings); a detector without such a floor returns ``detect``."""
        return self.detect(frame)


@runtime_checkable
class TextEmbedderLike(Protocol):
    """What the offline dense encoder needs from a text embedder (capnav.language.TextEmbedder)."""

    model_id: str
    dim: int

    def embed(self, texts: Sequence[str]) -> NDArray[np.float32]: ...


class DenseFeatureEncoder(ABC):
    """Per-pixel features ``Phi_t`` (eq. 6 and 10): ``encode(frame, detections) -> (H', W', D)``.

    ``H', W'`` may be smaller than the image (LSeg predicts at reduced resolution); pixel (u, v)
    samples cell ``(v * H' // H, u * W' // W)``. ``text_space`` names the text embedding space the
    features live in, so a query vector from the same embedder can be compared with them.
    """

    id: str = "encoder"
    dim: int = 0
    text_space: str = ""

    @abstractmethod
    def encode(self, frame: Frame, detections: Sequence[Detection]) -> NDArray[np.float32]:
        """Feature map (H', W', D) float32."""

    def encode_indexed(self, frame: Frame, detections: Sequence[Detection]
                       ) -> tuple[NDArray[np.int64], NDArray[np.float32]]:
        """The same map factored as ``table[grid]``: ``grid`` (H', W') row indices into ``table``
        (M, D). Encoders whose features repeat (one vector per label) override this so the mapper
        projects M rows instead of H' x W'; the default factors nothing (M = H' x W')."""
        phi = np.asarray(self.encode(frame, detections), dtype=np.float32)
        if phi.ndim != 3:
            raise FrameError(frame.index, f"encoder {self.id} returned shape {phi.shape}, expected (H', W', D)")
        hh, ww, d = phi.shape
        return np.arange(hh * ww, dtype=np.int64).reshape(hh, ww), phi.reshape(hh * ww, d)


def needs_truth_error(detector: Detector, where: str) -> InputError:
    """The one-line refusal of a truth-reading detector (``sim``) on data without truth images,
    naming the detectors that work on real images."""
    real = [n for n in DETECTORS.names() if n != "sim"]
    return InputError(f"{where} has no simulator truth images (gt_instance/gt_category), which detector "
                      f"{detector.id.split(':')[0]!r} reads; use a detector for real images: "
                      f"{', '.join(real[:-1])} or {real[-1]} (docs/perception.md)")


DETECTORS: Registry[Detector] = Registry("detector")
ENCODERS: Registry[DenseFeatureEncoder] = Registry("encoder")


def create_detector(name: str, **kwargs: Any) -> Detector:
    """Build a detector backend by name (``DETECTORS.names()`` lists them)."""
    return DETECTORS.create(name, **kwargs)


def create_encoder(name: str, **kwargs: Any) -> DenseFeatureEncoder:
    """Build a dense feature encoder backend by name (``ENCODERS.names()`` lists them)."""
    return ENCODERS.create(name, **kwargs)
