"""Any OpenAI-compatible chat-completions API with images (Ollama, vLLM, LM Studio, hosted).

Images go as ``data:image/png;base64`` URLs. The key comes from ``api_key_env`` (default
``OPENAI_API_KEY``) and is optional, since local servers need none. Timeouts and HTTP errors
become ``ModelError``; 429 becomes ``RateLimited`` honouring ``Retry-After``.
"""

from __future__ import annotations

import base64
import os
from typing import Any

from capnav.core.errors import ModelError, pip_hint
from capnav.language.vlm.base import VLMS, RateLimited


class OpenAICompatVLM:
    def __init__(self, model: str = "gpt-4o-mini", base_url: str | None = None, api_key_env: str = "OPENAI_API_KEY",
                 timeout: float = 30.0, temperature: float = 0.0, max_tokens: int = 128) -> None:
        try:
            import httpx
        except ImportError:
            raise ModelError(f"httpx is not installed: {pip_hint('capnav[openai]')}") from None
        self.base_url = (base_url or os.environ.get("OPENAI_BASE_URL") or "https://api.openai.com/v1").rstrip("/")
        headers = {"Content-Type": "application/json"}
        key = os.environ.get(api_key_env)
        if key:
            headers["Authorization"] = f"Bearer {key}"
        self._http = httpx.Client(timeout=timeout, headers=headers)
        self._timeout = timeout
        self.model = model
        self.model_id = f"openai:{model}"
        self.temperature = temperature
        self.max_tokens = max_tokens

    def ask(self, prompt: str, images: list[bytes]) -> str:
        import httpx

        content: list[dict[str, Any]] = [{"type": "text", "text": prompt}]
        for png in images:
            url = "data:image/png;base64," + base64.b64encode(png).decode("ascii")
            content.append({"type": "image_url", "image_url": {"url": url}})
        body = {"model": self.model, "messages": [{"role": "user", "content": content}],
                "temperature": self.temperature, "max_tokens": self.max_tokens}
        try:
            r = self._http.post(f"{self.base_url}/chat/completions", json=body)
        except httpx.TimeoutException:
            raise ModelError(f"{self.model_id} timed out after {self._timeout:g} s") from None
        except httpx.HTTPError as e:
            raise ModelError(f"{self.model_id} request failed: {type(e).__name__}: {e}") from None
        if r.status_code == 429:
            ra = r.headers.get("retry-after")
            try:
                wait = float(ra) if ra is not None else None
            except ValueError:
                wait = None
            raise RateLimited(f"{self.model_id} rate limited (429)", retry_after=wait)
        if r.status_code != 200:
            raise ModelError(f"{self.model_id} answered HTTP {r.status_code}: {r.text[:200]}")
        try:
            msg = r.json()["choices"][0]["message"]["content"]
        except (ValueError, KeyError, IndexError, TypeError):
            raise ModelError(f"{self.model_id} answer is not a chat completion: {r.text[:200]}") from None
        if isinstance(msg, list):  # some servers return content parts
            msg = "".join(p.get("text", "") for p in msg if isinstance(p, dict))
        if not isinstance(msg, str) or not msg.strip():
            raise ModelError(f"{self.model_id} returned an empty message")
        return msg

    def close(self) -> None:
        self._http.close()


@VLMS.register("openai")
def openai(**kwargs: Any) -> OpenAICompatVLM:
    return OpenAICompatVLM(**kwargs)
