from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from capnav.cli import app
from capnav.io.mapfile import save_map
from capnav.language import create_captioner, create_embedder, describe_map
from language.synth import living_scene, make_map


@pytest.fixture(scope="module")
def map_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("cli") / "scene.capnav"
    save_map(make_map(living_scene()), path)
    return path


def test_caption_then_query(map_file: Path, tmp_path: Path):
    runner = CliRunner()
    bare = runner.invoke(app, ["query", str(map_file), "the red sofa"])
    assert bare.exit_code != 0 and "no captions" in str(bare.exception)
    out = tmp_path / "described.capnav"
    r = runner.invoke(app, ["caption", str(map_file), "-o", str(out), "--no-progress"])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["query", str(out), "the red sofa", "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["found"] and d["chosen"]["id"] == 1 and d["chosen"]["caption"].startswith("SOFA")
    r = runner.invoke(app, ["query", str(out), "closest chair", "--robot", "1.5,4"])
    assert r.exit_code == 0 and "object 5" in r.stdout and "why:" in r.stdout and "runners-up" in r.stdout
    r = runner.invoke(app, ["query", str(out), "closest chair", "--robot", "oops"])
    assert r.exit_code != 0 and "X,Y" in str(r.exception)
    r = runner.invoke(app, ["query", str(out), "the piano"])
    assert r.exit_code == 1 and "not found" in r.stdout  # answered "not found": exit code 1
    r = runner.invoke(app, ["query", str(out), "the piano", "--json"])
    assert r.exit_code == 0 and json.loads(r.stdout)["found"] is False  # JSON carries the answer: exit 0


def test_mismatched_embedder_is_refused(map_file: Path, tmp_path: Path):
    from capnav.io.mapfile import load_map

    cmap = load_map(map_file)
    emb = create_embedder("minilm")
    describe_map(cmap, None, create_captioner("offline"), emb, progress=False)
    for o in cmap.objects:
        o.embedding_model = "another-model"
    path = tmp_path / "other.capnav"
    save_map(cmap, path)
    r = CliRunner().invoke(app, ["query", str(path), "the sofa"])
    assert r.exit_code != 0 and "another-model" in str(r.exception)
