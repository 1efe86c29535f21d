"""The captioner interface (paper 3.3): an object with its chosen views in, a schema caption out.

Remote backends (Gemini, OpenAI-compatible, local VLM) implement ``_ask``; ``RemoteCaptioner``
parses the answer against the schema, retries off-schema or failed answers with exponential
backoff, and finally falls back to the offline captioner with the reason recorded in
``caption_source`` ("fallback: <reason>"), so one bad answer never loses a map.
"""

from __future__ import annotations

import hashlib
import logging
import time
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from capnav.core.errors import CapNavError
from capnav.core.registry import Registry
from capnav.language.context import SceneContext
from capnav.language.prompts import caption_prompt, parse_caption
from capnav.language.vlm.base import RateLimited
from capnav.mapping.objects import MapObject

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Caption:
    text: str
    source: str  # backend model id, or "fallback: <reason>"


class Captioner(ABC):
    """``caption(obj, scene)`` returns a schema caption; ``cache_key`` identifies its inputs."""

    model_id: str

    @abstractmethod
    def caption(self, obj: MapObject, scene: SceneContext) -> Caption: ...

    def prompt(self, obj: MapObject) -> str:
        return caption_prompt(obj.label)

    def cache_key(self, obj: MapObject, scene: SceneContext) -> str:
        """Hash of the views' content, the prompt and the model (the paper's cached captions)."""
        h = hashlib.sha256()
        for v in obj.views:
            h.update(hashlib.sha256(v.frame_png).digest())
            h.update(hashlib.sha256(v.crop_png).digest())
        h.update(self.prompt(obj).encode())
        h.update(self.model_id.encode())
        return h.hexdigest()


CAPTIONERS: Registry[Captioner] = Registry("captioner", providers={
    "offline": "capnav.language.offline_captioner",
    **dict.fromkeys(["gemini", "openai", "hf-local"], "capnav.language.remote_captioners")})


def create_captioner(name: str = "offline", **kwargs: Any) -> Captioner:
    """Build a captioner by name: ``offline`` (default), ``gemini``, ``openai``, ``hf-local``."""
    return CAPTIONERS.create(name, **kwargs)


@dataclass(frozen=True)
class RetryPolicy:
    attempts: int = 3
    backoff: float = 1.0  # seconds, doubled per attempt
    max_backoff: float = 20.0


class RemoteCaptioner(Captioner):
    """A model that answers a prompt about images; retries, then falls back to ``fallback``."""

    def __init__(self, model_id: str, retry: RetryPolicy | None = None, fallback: Captioner | None = None,
                 sleep: Callable[[float], None] = time.sleep, use_crops: bool = False) -> None:
        self.model_id = model_id
        self.retry = retry or RetryPolicy()
        self._fallback = fallback
        self._sleep = sleep
        self.use_crops = use_crops

    @property
    def fallback(self) -> Captioner:
        if self._fallback is None:  # by name: this module must not import the offline captioner (an import circle)
            self._fallback = CAPTIONERS.create("offline")
        return self._fallback

    @abstractmethod
    def _ask(self, prompt: str, images: list[bytes]) -> str:
        """One model call: prompt plus PNG images in, raw text out; raise ModelError/RateLimited."""

    def images(self, obj: MapObject) -> list[bytes]:
        imgs = [v.crop_png if self.use_crops else v.frame_png for v in obj.views[:5]]
        return [b for b in imgs if b]

    def caption(self, obj: MapObject, scene: SceneContext) -> Caption:
        images = self.images(obj)
        if not images:
            return self._fall(obj, scene, "object has no views")
        prompt = self.prompt(obj)
        reason = "no attempt"
        for attempt in range(self.retry.attempts):
            try:
                return Caption(parse_caption(self._ask(prompt, images)), self.model_id)
            except RateLimited as e:
                reason = str(e)
                wait = e.retry_after if e.retry_after is not None else self.retry.backoff * 2**attempt
            except CapNavError as e:
                reason = str(e)
                wait = self.retry.backoff * 2**attempt
            if attempt + 1 < self.retry.attempts:
                self._sleep(min(wait, self.retry.max_backoff))
        return self._fall(obj, scene, reason)

    def _fall(self, obj: MapObject, scene: SceneContext, reason: str) -> Caption:
        log.warning("%s: object %d falls back to the offline captioner: %s", self.model_id, obj.id, reason)
        text = self.fallback.caption(obj, scene).text
        return Caption(text, f"fallback: {reason} [{self.model_id}]")
