from __future__ import annotations

import json

import numpy as np
import pytest

from capnav.core.errors import InputError
from capnav.language import SceneContext, create_captioner, create_embedder
from capnav.language.prompts import parse_verdict
from capnav.retrieval import RetrievalConfig, Retriever, create_verifier, parse_instruction
from capnav.retrieval.ranking import cosine_scores, mmr, top_k
from capnav.retrieval.verifier import Candidate, VLMVerifier
from language.synth import captioned_map, living_scene, make_map


@pytest.fixture(scope="module")
def emb():
    return create_embedder("minilm")


@pytest.fixture()
def cmap(emb):
    return captioned_map(living_scene(), emb)


def test_attribute_superlative_relation_room(cmap, emb):
    r = Retriever(cmap, emb)
    assert r.query("go to the red couch").chosen.id == 1
    assert r.query("the grey sofa please").chosen.id == 2
    assert r.query("the smallest sofa").chosen.id == 2
    assert r.query("Find the biggest settee.").chosen.id == 1
    assert r.query("the chair next to the bed").chosen.id == 4
    assert r.query("In the kitchen, find the chair.").chosen.id == 5
    res = r.query("the bed")
    assert res.found and res.chosen.id == 3 and res.chosen.caption in res.reason


def test_closest_uses_grid_distance(cmap, emb):
    r = Retriever(cmap, emb, config=RetrievalConfig(distance="straight"))  # eq. 17 (walking: test_walking_distance)
    a = r.query("the closest chair", robot_xy=(6.5, 3.0))
    b = r.query("the closest chair", robot_xy=(1.5, 4.0))
    assert (a.chosen.id, b.chosen.id) == (4, 5) and a.mode == "closest" and a.predicate == "closest"
    assert a.distance_m == pytest.approx(np.hypot(0.5, 0.6), abs=0.1)
    assert r.query("the farthest chair", robot_xy=(6.5, 3.0)).chosen.id == 5
    # Category only with a robot position: the attribute heuristic makes it a "closest" query ...
    assert r.query("chair", robot_xy=(1.5, 4.0)).chosen.id == 5
    # ... and without the heuristic it is a pure semantic query (eq. 16 only).
    plain = Retriever(cmap, emb, config=RetrievalConfig(use_attribute_heuristic=False))
    res = plain.query("the closest chair", robot_xy=(1.5, 4.0))
    assert res.mode == "semantic" and res.chosen.label == "chair"


def test_not_found(cmap, emb):
    r = Retriever(cmap, emb)
    for text in ("the bathtub", "go to the piano", "Find the washing machine."):
        res = r.query(text)
        assert not res.found and res.chosen is None and res.reason.startswith("Not found")
    noverify = Retriever(cmap, emb, config=RetrievalConfig(use_verifier=False))
    assert not noverify.query("the bathtub").found


def test_result_json_and_timings(cmap, emb):
    res = Retriever(cmap, emb).query("the red sofa", robot_xy=(0.0, 0.0))
    d = json.loads(json.dumps(res.to_dict()))
    assert d["chosen"]["id"] == 1 and d["found"] and set(d["timings"]) == {"embed", "rank", "verify"}
    assert len(d["runners_up"]) <= 5 and all(r["id"] != 1 for r in d["runners_up"])
    assert d["query"]["colors"] == ["red"]


def test_bad_maps_and_inputs(cmap, emb):
    r = Retriever(cmap, emb)
    with pytest.raises(InputError, match="empty"):
        r.query("  ")
    with pytest.raises(InputError, match="robot position"):
        r.query("the sofa", robot_xy=(float("nan"), 0.0))
    other = create_embedder("minilm")
    other.model_id = "some-other-model"
    with pytest.raises(InputError, match="embedded with"):
        Retriever(cmap, other)
    for o in cmap.objects:
        o.caption, o.embedding = None, None
    with pytest.raises(InputError, match="no captions"):
        Retriever(cmap, emb)


def test_ranking_helpers():
    rng = np.random.default_rng(0)
    E = rng.normal(size=(6, 8)).astype(np.float32)
    E /= np.linalg.norm(E, axis=1, keepdims=True)
    q = E[2]
    s = cosine_scores(E, q)
    np.testing.assert_allclose(s, E @ q, atol=1e-6)
    assert top_k(s, 3)[0] == 2 and len(top_k(s, 3)) == 3
    assert list(top_k(s, 10, among=np.array([4, 5]))) == sorted([4, 5], key=lambda i: -s[i])
    E2 = np.concatenate([E[:1], E[:1], E[1:2]])  # two identical rows
    order = mmr(E2, np.array([1.0, 0.99, 0.5], np.float32), np.array([0, 1, 2]), lam=0.5)
    assert list(order) == [0, 2, 1]  # the duplicate is pushed back
    assert list(mmr(E2, np.array([1.0, 0.99, 0.5], np.float32), np.array([0, 1, 2]), lam=1.0)) == [0, 1, 2]


class FakeVLM:
    """Deterministic stand-in client for the verifier protocol (answers in order)."""

    model_id = "fake-vlm"

    def __init__(self, answers):
        self.answers = list(answers)
        self.prompts = []

    def ask(self, prompt, images):
        self.prompts.append(prompt)
        return self.answers.pop(0)


def test_vlm_verifier_protocol_cache_and_fallback(cmap, emb):
    q = parse_instruction("the grey sofa")
    batch = [Candidate(cmap.objects[0], 0.6, 0), Candidate(cmap.objects[1], 0.5, 1)]
    fake = FakeVLM(["ACCEPT 2: the grey one matches"])
    v = VLMVerifier(fake, sleep=lambda s: None)
    out = v.verify(q, batch)
    assert out.index == 1 and out.reason == "the grey one matches"
    assert "You are helping a mobile robot find a grey sofa." in fake.prompts[0]
    assert "Object 2: SOFA" in fake.prompts[0]
    assert v.verify(q, batch).index == 1 and len(fake.prompts) == 1  # cached decision
    bad = VLMVerifier(FakeVLM(["maybe the second?", "ACCEPT 7: x", "I think so"]), sleep=lambda s: None)
    out = bad.verify(q, batch)
    assert out.index == 1 and "offline fallback" in out.reason
    rej = VLMVerifier(FakeVLM(["REJECT ALL: none of these is a bathtub"]))
    assert rej.verify(parse_instruction("the bathtub"), batch).index is None
    r = Retriever(cmap, emb, verifier=VLMVerifier(FakeVLM(["REJECT ALL: no"] * 10)))
    assert not r.query("the sofa").found
    assert cmap.caches["verifications"]  # decisions persist with the map


def test_parse_verdict_strict():
    assert parse_verdict("ACCEPT 1: ok", 3).index == 0
    assert parse_verdict("REJECT ALL: nothing", 3).index is None
    for bad in ("accept one", "ACCEPT 4: too far", "Sure! ACCEPT 1: x"):
        with pytest.raises(Exception):  # noqa: B017
            parse_verdict(bad, 3)


def test_verifier_registry():
    assert create_verifier("none").name == "none"
    assert create_verifier("offline").name == "offline"
    with pytest.raises(InputError):
        create_verifier("nope")


def test_plants_are_told_apart_by_their_pots(emb):
    """Leaves dominate a plant's colours; "the plant in the blue pot" reads the base of the object."""
    from language.synth import make_obj

    plants = []
    for oid, pot, x in ((1, (40, 70, 170), 0.0), (2, (178, 34, 34), 2.0)):
        o = make_obj(oid, "plant", (x, 0.0), (0.5, 0.5, 1.0), (46, 120, 60))
        low = o.points[:, 2] < 0.25
        o.colors[low] = pot
        plants.append(o)
    scene = SceneContext(plants)
    cap = create_captioner("offline")
    for o in plants:
        o.caption = cap.caption(o, scene).text
        o.embedding, o.embedding_model = emb.embed([o.caption])[0], emb.model_id
    assert "in a blue pot" in plants[0].caption and "in a red pot" in plants[1].caption
    r = Retriever(make_map(plants), emb)
    assert r.query("the plant in the red pot").chosen.id == 2
    assert r.query("the plant with the blue pot").chosen.id == 1
