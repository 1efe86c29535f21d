"""Shared test helpers: a deterministic random-vector text embedder (a real backend's stand-in for
unit tests of the geometry; end-to-end tests use the real MiniLM embedder)."""

from __future__ import annotations

import pytest
from _synth_scene import HashEmbedder


@pytest.fixture
def embedder() -> HashEmbedder:
    return HashEmbedder()
