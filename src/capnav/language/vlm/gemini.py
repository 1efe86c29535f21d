"""Gemini through the google-genai SDK (the paper's gemini-2.5-flash-lite by default).

The API key is read from the environment (``GEMINI_API_KEY`` or ``GOOGLE_API_KEY``) only; it is
never written to disk, logged, or put in an error message. ``base_url`` points the SDK at another
endpoint (a proxy, or the tests' local server speaking the generateContent protocol). The SDK's
own retries are off: the captioner / verifier retry with backoff and record why they gave up.
"""

from __future__ import annotations

import os
from typing import Any

from capnav.core.errors import ModelError, pip_hint
from capnav.language.vlm.base import VLMS, RateLimited

DEFAULT_MODEL = "gemini-2.5-flash-lite"


def api_key_from_env() -> str:
    for var in ("GEMINI_API_KEY", "GOOGLE_API_KEY"):
        key = os.environ.get(var)
        if key:
            return key
    raise ModelError("no Gemini API key: set GEMINI_API_KEY or GOOGLE_API_KEY in the environment")


class GeminiVLM:
    def __init__(self, model: str = DEFAULT_MODEL, base_url: str | None = None, timeout: float = 30.0,
                 temperature: float = 0.0, max_output_tokens: int = 128) -> None:
        try:
            from google import genai
            from google.genai import types
        except ImportError:
            raise ModelError(f"google-genai is not installed: {pip_hint('capnav[gemini]')}") from None
        self._types = types
        opts: dict[str, Any] = {"timeout": int(timeout * 1000)}
        if base_url:
            opts["base_url"] = base_url
        self._client = genai.Client(api_key=api_key_from_env(), http_options=types.HttpOptions(**opts))
        self.model = model
        self.model_id = f"gemini:{model}"
        self._config = types.GenerateContentConfig(temperature=temperature, max_output_tokens=max_output_tokens)

    def ask(self, prompt: str, images: list[bytes]) -> str:
        from google.genai import errors

        t = self._types
        contents: list[Any] = [t.Part.from_bytes(data=png, mime_type="image/png") for png in images]
        contents.append(prompt)
        try:
            resp = self._client.models.generate_content(model=self.model, contents=contents, config=self._config)
        except errors.APIError as e:
            if e.code == 429:
                raise RateLimited(f"Gemini rate limit (429): {e.message or e.status}") from None
            raise ModelError(f"Gemini error {e.code}: {e.message or e.status}") from None
        except Exception as e:  # transport errors: timeouts, refused connections
            raise ModelError(f"Gemini request failed: {type(e).__name__}: {e}") from None
        text = resp.text
        if not text:
            raise ModelError("Gemini returned no text (blocked or empty candidate)")
        return text


@VLMS.register("gemini")
def gemini(**kwargs: Any) -> GeminiVLM:
    return GeminiVLM(**kwargs)
