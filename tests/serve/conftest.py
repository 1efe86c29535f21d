"""A small captioned map for the server tests (synthetic living room: no simulator needed)."""

from __future__ import annotations

from pathlib import Path

import pytest

from capnav.api import CapNav
from capnav.language import create_captioner, create_embedder, describe_map
from language.synth import grid_with_wall, living_scene, make_map


@pytest.fixture(scope="session")
def served_map(tmp_path_factory: pytest.TempPathFactory) -> Path:
    cmap = make_map(living_scene(), grid_with_wall(-1, -1, 9, 7, wall_x=3.8, door=(2.5, 3.5)))
    describe_map(cmap, None, create_captioner("offline"), create_embedder("minilm"), progress=False)
    path = tmp_path_factory.mktemp("serve") / "living.capnav"
    CapNav(cmap).save(path)
    return path
