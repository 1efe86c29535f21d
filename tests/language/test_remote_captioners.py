"""Gemini and OpenAI-compatible captioners against a local server speaking the real protocols."""

from __future__ import annotations

import base64

import pytest

from capnav.core.errors import ModelError
from capnav.language import RetryPolicy, SceneContext, create_captioner
from capnav.language.prompts import CAPTION_PROMPT
from capnav.mapping.objects import ObjectView

from .http_fake import Script, serve
from .synth import living_scene

GOOD = "WHITE SOFA, a white sectional sofa with curved armrests."
NO_WAIT = RetryPolicy(attempts=3, backoff=0.0)


@pytest.fixture()
def obj():
    o = living_scene()[0]
    png = base64.b64decode("iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8DwHwAFBQIAX8jx0gAAAABJ"
                           "RU5ErkJggg==")
    o.views = [ObjectView(0, (0, 0, 1, 1), 1.0, png, png), ObjectView(1, (0, 0, 1, 1), 0.9, png, png)]
    return o


@pytest.fixture()
def gemini_key(monkeypatch):
    monkeypatch.delenv("GOOGLE_API_KEY", raising=False)
    monkeypatch.setenv("GEMINI_API_KEY", "test-key-123")


def _sleeps():
    waits: list[float] = []
    return waits, waits.append


def test_gemini_protocol_prompt_images_and_key(obj, gemini_key):
    script = Script([("text", GOOD)])
    with serve(script, "gemini") as url:
        cap = create_captioner("gemini", base_url=url, retry=NO_WAIT)
        out = cap.caption(obj, SceneContext([obj]))
    assert out.text == GOOD and out.source == "gemini:gemini-2.5-flash-lite"
    req = script.requests[0]
    assert req["path"].endswith("/models/gemini-2.5-flash-lite:generateContent")
    assert req["headers"].get("x-goog-api-key") == "test-key-123"
    parts = req["body"]["contents"][0]["parts"]
    assert sum("inlineData" in p or "inline_data" in p for p in parts) == 2
    text = " ".join(p.get("text", "") for p in parts)
    assert CAPTION_PROMPT in text and "Category hint: sofa" in text


def test_gemini_rate_limit_then_success(obj, gemini_key):
    script = Script([("status", 429), ("text", GOOD)])
    waits, sleep = _sleeps()
    with serve(script, "gemini") as url:
        cap = create_captioner("gemini", base_url=url, retry=RetryPolicy(attempts=3, backoff=0.01), sleep=sleep)
        out = cap.caption(obj, SceneContext([obj]))
    assert out.text == GOOD and len(script.requests) == 2 and waits == [0.01]


def test_gemini_off_schema_falls_back_with_reason(obj, gemini_key):
    script = Script([("text", "This is a nice sofa. It is white.")])
    with serve(script, "gemini") as url:
        cap = create_captioner("gemini", base_url=url, retry=NO_WAIT, sleep=lambda s: None)
        out = cap.caption(obj, SceneContext([obj]))
    assert len(script.requests) == 3
    assert out.source.startswith("fallback:") and "UPPERCASE" in out.source
    assert out.text.startswith("SOFA, ")  # the offline caption
    assert "test-key-123" not in out.source


def test_gemini_needs_a_key_from_the_environment(monkeypatch):
    monkeypatch.delenv("GEMINI_API_KEY", raising=False)
    monkeypatch.delenv("GOOGLE_API_KEY", raising=False)
    with pytest.raises(ModelError, match="GEMINI_API_KEY"):
        create_captioner("gemini")


def test_openai_protocol_and_images(obj, monkeypatch):
    monkeypatch.setenv("OPENAI_API_KEY", "sk-local")
    script = Script([("text", GOOD)])
    with serve(script, "openai") as url:
        cap = create_captioner("openai", base_url=url, model="llava", retry=NO_WAIT)
        out = cap.caption(obj, SceneContext([obj]))
    assert out.text == GOOD and out.source == "openai:llava"
    req = script.requests[0]
    assert req["path"] == "/chat/completions" and req["headers"]["Authorization"] == "Bearer sk-local"
    content = req["body"]["messages"][0]["content"]
    assert content[0]["type"] == "text" and CAPTION_PROMPT in content[0]["text"]
    assert [c["image_url"]["url"][:22] for c in content[1:]] == ["data:image/png;base64,"] * 2


def test_openai_429_retry_after_then_success(obj):
    script = Script([("status", 429), ("status", 429), ("text", GOOD)])
    waits, sleep = _sleeps()
    with serve(script, "openai") as url:
        cap = create_captioner("openai", base_url=url, retry=RetryPolicy(attempts=3, backoff=5.0), sleep=sleep)
        out = cap.caption(obj, SceneContext([obj]))
    assert out.text == GOOD and waits == [0.0, 0.0]  # the server's Retry-After, not the 5 s backoff


def test_openai_timeout_and_garbage_fall_back(obj):
    script = Script([("sleep", 1.0, GOOD)])
    with serve(script, "openai") as url:
        cap = create_captioner("openai", base_url=url, timeout=0.2, retry=RetryPolicy(attempts=2, backoff=0.0),
                               sleep=lambda s: None)
        out = cap.caption(obj, SceneContext([obj]))
    assert out.source.startswith("fallback:") and "timed out" in out.source
    script = Script([("raw", "<html>not json</html>")])
    with serve(script, "openai") as url:
        cap = create_captioner("openai", base_url=url, retry=RetryPolicy(attempts=1), sleep=lambda s: None)
        out = cap.caption(obj, SceneContext([obj]))
    assert "not a chat completion" in out.source


def test_no_views_no_request(obj):
    obj.views = []
    script = Script([("text", GOOD)])
    with serve(script, "openai") as url:
        out = create_captioner("openai", base_url=url).caption(obj, SceneContext([obj]))
    assert script.requests == [] and out.source.startswith("fallback: object has no views")
