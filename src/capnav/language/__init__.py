"""Language stage: view selection, captioners, text embedders and their caches (paper 3.3).

Names are imported on first use (PEP 562), and backends register when first asked for (the
registries' providers): answering a query reads the parser's and the retriever's modules, not the
captioners, view selection or the remote model clients."""

from __future__ import annotations

from typing import TYPE_CHECKING

from capnav.core.lazy import lazy_exports

if TYPE_CHECKING:
    from capnav.language.captioner import CAPTIONERS, Caption, Captioner, RetryPolicy, create_captioner
    from capnav.language.context import SceneContext
    from capnav.language.describe import DescribeReport, describe_map
    from capnav.language.embedder import EMBEDDERS, TextEmbedder, create_embedder
    from capnav.language.offline_captioner import ObservationCaptioner
    from capnav.language.views import ViewConfig, select_views, select_views_all

#: Public name -> the submodule that defines it.
_SOURCES = {
    **dict.fromkeys(["CAPTIONERS", "Caption", "Captioner", "RetryPolicy", "create_captioner"], "captioner"),
    "SceneContext": "context",
    **dict.fromkeys(["DescribeReport", "describe_map"], "describe"),
    **dict.fromkeys(["EMBEDDERS", "TextEmbedder", "create_embedder"], "embedder"),
    "ObservationCaptioner": "offline_captioner",
    **dict.fromkeys(["ViewConfig", "select_views", "select_views_all"], "views"),
}

__getattr__, __dir__ = lazy_exports(__name__, _SOURCES)

__all__ = ["CAPTIONERS", "EMBEDDERS", "Caption", "Captioner", "DescribeReport", "ObservationCaptioner",
           "RetryPolicy", "SceneContext", "TextEmbedder", "ViewConfig", "create_captioner", "create_embedder",
           "describe_map", "select_views", "select_views_all"]
