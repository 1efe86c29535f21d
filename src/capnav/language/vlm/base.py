"""The client interface every vision-language backend implements, and its registry."""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

from capnav.core.errors import ModelError
from capnav.core.registry import Registry


class RateLimited(ModelError):
    """HTTP 429 or equivalent; ``retry_after`` seconds if the server said so."""

    def __init__(self, message: str, retry_after: float | None = None) -> None:
        super().__init__(message)
        self.retry_after = retry_after


@runtime_checkable
class VisionLanguageModel(Protocol):
    model_id: str

    def ask(self, prompt: str, images: list[bytes]) -> str:
        """Answer ``prompt`` about PNG ``images``; raise ``ModelError`` / ``RateLimited``."""
        ...


VLMS: Registry[VisionLanguageModel] = Registry("vision-language model", providers={
    "gemini": "capnav.language.vlm.gemini", "openai": "capnav.language.vlm.openai_compat",
    "hf-local": "capnav.language.vlm.hf_local"})


def create_vlm(name: str, **kwargs: Any) -> VisionLanguageModel:
    """``gemini`` (google-genai), ``openai`` (any OpenAI-compatible chat API), ``hf-local``."""
    return VLMS.create(name, **kwargs)
