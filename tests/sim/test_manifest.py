"""The scene manifest round-trips and rejects damaged files."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from capnav.core.errors import DatasetError
from capnav.sim import SceneManifest, Simulator


def test_manifest_round_trip(small_sim: Simulator, tmp_path: Path) -> None:
    m = small_sim.manifest
    p = tmp_path / "manifest.json"
    m.save(p)
    back = SceneManifest.load(p)
    assert back == m
    assert back.object(1).id == 1
    assert {o.id for o in back.by_category(m.objects[0].category)} >= {m.objects[0].id}


def test_manifest_errors(tmp_path: Path, small_sim: Simulator) -> None:
    with pytest.raises(DatasetError, match="not found"):
        SceneManifest.load(tmp_path / "nope.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(DatasetError, match="not valid JSON"):
        SceneManifest.load(bad)
    data = json.loads(small_sim.manifest.model_dump_json())
    data["version"] = 99
    bad.write_text(json.dumps(data))
    with pytest.raises(DatasetError, match="version"):
        SceneManifest.load(bad)
    data["version"] = 1
    del data["objects"][0]["category"]
    bad.write_text(json.dumps(data))
    with pytest.raises(DatasetError, match="malformed"):
        SceneManifest.load(bad)
