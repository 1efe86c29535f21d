"""The optimised-graph copy of an ONNX embedder: written once, loaded after, same vectors bit for
bit, and a damaged or stale copy rebuilt rather than trusted."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from capnav.language import create_embedder

TEXTS = ["the white sofa with curved edges", "somewhere to put my coffee down", "the closest table"]


def _copies(folder: Path) -> list[Path]:
    return sorted(folder.glob("*.onnx"))


def test_copy_is_written_once_and_gives_the_same_vectors(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CAPNAV_ONNX_CACHE", "off")
    reference = create_embedder("minilm").embed(TEXTS)
    monkeypatch.setenv("CAPNAV_ONNX_CACHE", str(tmp_path))
    first = create_embedder("minilm").embed(TEXTS)  # optimises and writes the copy
    (copy,) = _copies(tmp_path)
    meta = json.loads(copy.with_suffix(".json").read_text())
    assert meta["source_sha256"][:16] in copy.name and meta["onnxruntime"] in copy.name
    stamp = copy.stat().st_mtime_ns
    second = create_embedder("minilm").embed(TEXTS)  # loads the copy, optimisation off
    assert copy.stat().st_mtime_ns == stamp
    np.testing.assert_array_equal(first, reference)
    np.testing.assert_array_equal(second, reference)


def test_damaged_copy_is_rebuilt(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                 caplog: pytest.LogCaptureFixture) -> None:
    monkeypatch.setenv("CAPNAV_ONNX_CACHE", str(tmp_path))
    reference = create_embedder("minilm").embed(TEXTS)
    (copy,) = _copies(tmp_path)
    copy.write_bytes(copy.read_bytes()[:1000])  # truncated by a full disk or a killed writer
    with caplog.at_level("WARNING"):
        again = create_embedder("minilm").embed(TEXTS)
    assert "does not match its recorded sha256" in caplog.text
    np.testing.assert_array_equal(again, reference)
    meta = json.loads(copy.with_suffix(".json").read_text())
    from capnav.core.checksum import sha256_file
    assert sha256_file(copy) == meta["sha256"]  # rebuilt whole


def test_unwritable_folder_falls_back_to_memory(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                caplog: pytest.LogCaptureFixture) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("CAPNAV_ONNX_CACHE", str(blocker / "onnx"))
    with caplog.at_level("WARNING"):
        vecs = create_embedder("minilm").embed(TEXTS)
    assert "optimising in memory" in caplog.text and vecs.shape == (3, 384)
