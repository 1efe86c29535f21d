"""Captioners backed by a vision-language model client (Gemini, OpenAI-compatible, local HF)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from capnav.language.captioner import CAPTIONERS, Captioner, RemoteCaptioner, RetryPolicy
from capnav.language.vlm.base import VisionLanguageModel, create_vlm


class VLMCaptioner(RemoteCaptioner):
    """The paper's caption prompt with the category hint, sent with up to five framed views."""

    def __init__(self, client: VisionLanguageModel, retry: RetryPolicy | None = None,
                 fallback: Captioner | None = None, sleep: Callable[[float], None] | None = None,
                 use_crops: bool = False) -> None:
        kw: dict[str, Any] = {} if sleep is None else {"sleep": sleep}
        super().__init__(client.model_id, retry=retry, fallback=fallback, use_crops=use_crops, **kw)
        self.client = client

    def _ask(self, prompt: str, images: list[bytes]) -> str:
        return self.client.ask(prompt, images)


def _factory(backend: str) -> Callable[..., VLMCaptioner]:
    def make(retry: RetryPolicy | None = None, fallback: Captioner | None = None,
             sleep: Callable[[float], None] | None = None, use_crops: bool = False, **client_kw: Any) -> VLMCaptioner:
        return VLMCaptioner(create_vlm(backend, **client_kw), retry=retry, fallback=fallback, sleep=sleep,
                            use_crops=use_crops)

    make.__doc__ = f"Captioner over the {backend!r} vision-language client."
    return make


for _name in ("gemini", "openai", "hf-local"):
    CAPTIONERS.register(_name)(_factory(_name))
