"""Perception stage: detectors (eq. 9) and dense feature encoders (LSeg's Phi_t), chosen by name."""

from capnav.perception import coco_detector as _coco_detector  # noqa: F401  (registers backends; cv2 loads when built)
from capnav.perception import label_encoder as _label_encoder  # noqa: F401
from capnav.perception import owl_detector as _owl_detector  # noqa: F401  (torch/transformers load when built)
from capnav.perception import sim_detector as _sim_detector  # noqa: F401
from capnav.perception.base import (
    DETECTORS,
    ENCODERS,
    DenseFeatureEncoder,
    Detection,
    Detector,
    TextEmbedderLike,
    box_from_mask,
    create_detector,
    create_encoder,
    validate_detections,
)
from capnav.perception.coco_detector import CenterNetDetector, CocoDetector, YoloFastestDetector
from capnav.perception.label_encoder import LabelEmbeddingEncoder
from capnav.perception.owl_detector import OwlDetector
from capnav.perception.sim_detector import NOISE_PRESETS, SimDetector, SimNoise

__all__ = [
    "DETECTORS",
    "ENCODERS",
    "NOISE_PRESETS",
    "CenterNetDetector",
    "CocoDetector",
    "DenseFeatureEncoder",
    "Detection",
    "Detector",
    "LabelEmbeddingEncoder",
    "OwlDetector",
    "SimDetector",
    "SimNoise",
    "TextEmbedderLike",
    "YoloFastestDetector",
    "box_from_mask",
    "create_detector",
    "create_encoder",
    "validate_detections",
]
