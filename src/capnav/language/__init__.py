"""Language stage: view selection, captioners, text embedders and their caches (paper 3.3)."""

import capnav.language.remote_captioners  # noqa: F401
from capnav.language import offline_captioner as _offline  # noqa: F401  (registers backends)
from capnav.language import onnx_embedder as _onnx_embedder  # noqa: F401
from capnav.language import st_embedder as _st_embedder  # noqa: F401
from capnav.language.captioner import CAPTIONERS, Caption, Captioner, RetryPolicy, create_captioner
from capnav.language.context import SceneContext
from capnav.language.describe import DescribeReport, describe_map
from capnav.language.embedder import EMBEDDERS, TextEmbedder, create_embedder
from capnav.language.offline_captioner import ObservationCaptioner
from capnav.language.views import ViewConfig, select_views, select_views_all

__all__ = ["CAPTIONERS", "EMBEDDERS", "Caption", "Captioner", "DescribeReport", "ObservationCaptioner",
           "RetryPolicy", "SceneContext", "TextEmbedder", "ViewConfig", "create_captioner", "create_embedder",
           "describe_map", "select_views", "select_views_all"]
