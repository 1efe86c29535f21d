"""A small captioned map for the server tests (synthetic living room: no simulator needed)."""

from __future__ import annotations

from pathlib import Path

import pytest

from language.synth import described_living_map


@pytest.fixture(scope="session")
def served_map(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return described_living_map(tmp_path_factory.mktemp("serve"))
