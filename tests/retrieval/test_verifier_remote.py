"""The AGENT verifier over Gemini and an OpenAI-compatible API, against a local server."""

from __future__ import annotations

import pytest

from capnav.language import RetryPolicy
from capnav.language.prompts import VERIFY_PROMPT
from capnav.retrieval import create_verifier, parse_instruction
from capnav.retrieval.verifier import Candidate
from language.http_fake import Script, serve
from language.synth import living_scene

NO_WAIT = RetryPolicy(attempts=2, backoff=0.0)


@pytest.fixture()
def batch():
    objs = living_scene()[:2]
    objs[0].caption = "SOFA, a large red fabric sofa."
    objs[1].caption = "SOFA, a small grey sofa."
    return [Candidate(objs[0], 0.6, 0), Candidate(objs[1], 0.5, 1)]


def test_gemini_verifier(batch, monkeypatch):
    monkeypatch.setenv("GEMINI_API_KEY", "k")
    script = Script([("text", "ACCEPT 2: it is the grey sofa")])
    with serve(script, "gemini") as url:
        v = create_verifier("gemini", base_url=url, retry=NO_WAIT, sleep=lambda s: None)
        out = v.verify(parse_instruction("the grey couch"), batch)
    assert out.index == 1 and out.reason == "it is the grey sofa"
    text = " ".join(p.get("text", "") for p in script.requests[0]["body"]["contents"][0]["parts"])
    assert VERIFY_PROMPT.format(object_type="grey sofa") in text and "Object 2: SOFA, a small grey sofa." in text


def test_openai_verifier_off_schema_then_fallback(batch):
    script = Script([("text", "Probably the second one.")])
    with serve(script, "openai") as url:
        v = create_verifier("openai", base_url=url, retry=NO_WAIT, sleep=lambda s: None)
        out = v.verify(parse_instruction("the grey sofa"), batch)
    assert len(script.requests) == 2 and out.index == 1 and "offline fallback" in out.reason
    script = Script([("status", 429), ("text", "REJECT ALL: no bathtub here")])
    with serve(script, "openai") as url:
        v = create_verifier("openai", base_url=url, retry=NO_WAIT, sleep=lambda s: None)
        out = v.verify(parse_instruction("the bathtub"), batch)
    assert out.index is None and out.reason == "no bathtub here"
