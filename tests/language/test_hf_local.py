"""The local-VLM path on a tiny random LLaVA the test builds: real loading, preprocessing, greedy
generation and decoding; its random answers are off-schema, so the captioner must fall back."""

from __future__ import annotations

import io
from pathlib import Path

import pytest
from PIL import Image

from capnav.core.errors import ModelError
from capnav.language import RetryPolicy, SceneContext, create_captioner
from capnav.language.vlm import create_vlm
from capnav.mapping.objects import ObjectView

from .synth import living_scene


def _png(color: tuple[int, int, int]) -> bytes:
    b = io.BytesIO()
    Image.new("RGB", (40, 30), color).save(b, format="PNG")
    return b.getvalue()


def test_generates_deterministically(tiny_vlm: Path):
    vlm = create_vlm("hf-local", path=tiny_vlm, max_new_tokens=6)
    a = vlm.ask("describe the sofa", [_png((200, 10, 10)), _png((10, 10, 200))])
    assert isinstance(a, str) and a == vlm.ask("describe the sofa", [_png((200, 10, 10)), _png((10, 10, 200))])
    assert vlm.model_id == f"hf-local:{tiny_vlm.name}"


def test_captioner_falls_back_on_random_answers(tiny_vlm: Path):
    obj = living_scene()[0]
    obj.views = [ObjectView(0, (0, 0, 10, 10), 1.0, _png((200, 10, 10)), _png((200, 10, 10)))]
    cap = create_captioner("hf-local", path=tiny_vlm, max_new_tokens=6, retry=RetryPolicy(attempts=2, backoff=0.0),
                           sleep=lambda s: None)
    out = cap.caption(obj, SceneContext([obj]))
    assert out.source.startswith("fallback:") and f"hf-local:{tiny_vlm.name}" in out.source
    assert out.text.startswith("SOFA, ")


def test_missing_folder(tmp_path: Path):
    with pytest.raises(ModelError, match="not found"):
        create_vlm("hf-local", path=tmp_path / "none")
    (tmp_path / "empty").mkdir()
    with pytest.raises(ModelError, match="cannot load"):
        create_vlm("hf-local", path=tmp_path / "empty")
