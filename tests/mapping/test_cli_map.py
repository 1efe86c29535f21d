"""`capnav map` and `capnav map-eval` on a small dataset folder written from synthetic frames."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from _synth_scene import default_boxes, orbit
from typer.testing import CliRunner

from capnav.cli import app
from capnav.core.categories import BY_ID
from capnav.io.dataset import DatasetWriter
from capnav.sim.manifest import ObjectInstance, Room, SceneManifest


@pytest.fixture(scope="module")
def dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("ds")
    frames = orbit(24)
    with DatasetWriter(root, frames[0].K) as w:
        for f in frames:
            w.write(f)
    objs = []
    for b in default_boxes():
        c = b.center
        size = [hi - lo for lo, hi in zip(b.lo, b.hi, strict=True)]
        objs.append(ObjectInstance(
            id=b.instance, category=BY_ID[b.category].name, category_id=b.category, color_name="grey",
            color_rgb=b.color, material="wood", shape="box", size=tuple(size), center=tuple(c), yaw=0.0,
            footprint=[(b.lo[0], b.lo[1]), (b.hi[0], b.lo[1]), (b.hi[0], b.hi[1]), (b.lo[0], b.hi[1])],
            room="r0", model="primitive:box"))
    SceneManifest(seed=123456, bounds=(-3, -3, 3, 3), wall_height=2.5,
                  rooms=[Room(id="r0", name="living room", polygon=[(-3, -3), (3, -3), (3, 3), (-3, 3)])],
                  objects=objs).save(root / "manifest.json")
    return root


def test_map_and_eval(dataset: Path, tmp_path: Path) -> None:
    out = tmp_path / "m.capnav"
    r = CliRunner().invoke(app, ["map", str(dataset), "-o", str(out), "--noise", "oracle", "--no-progress"])
    assert r.exit_code == 0, r.output
    assert out.is_file() and "objects" in r.output
    from capnav.io.mapfile import load_map

    assert "scene_seed" not in load_map(out).meta  # not a simulator recording: no apartment to name
    js = tmp_path / "q.json"
    r = CliRunner().invoke(app, ["map-eval", str(out), "--manifest", str(dataset / "manifest.json"),
                                 "--json", str(js)])
    assert r.exit_code == 0, r.output
    assert "instance recall" in r.output and "occupancy IoU" in r.output
    q = json.loads(js.read_text())
    assert q["precision"] == 1.0 and q["duplicate_rate"] == 0.0 and q["category_accuracy"] == 1.0


def test_missing_frame_is_skipped_and_named(dataset: Path, tmp_path: Path) -> None:
    bad = tmp_path / "bad"
    bad.mkdir()
    for p in dataset.rglob("*"):
        if p.is_file():
            q = bad / p.relative_to(dataset)
            q.parent.mkdir(parents=True, exist_ok=True)
            q.write_bytes(p.read_bytes())
    (bad / "depth" / "000005.png").unlink()
    (bad / "rgb" / "000007.png").write_bytes(b"not a png")
    out = tmp_path / "m.capnav"
    r = CliRunner().invoke(app, ["map", str(bad), "-o", str(out), "--noise", "oracle", "--no-progress"])
    assert r.exit_code == 0, r.output
    assert "skipped frame 5" in r.output and "skipped frame 7" in r.output
    r = CliRunner().invoke(app, ["map", str(bad), "-o", str(out), "--strict", "--no-progress"])
    assert r.exit_code != 0 and "frame 5" in str(r.exception)


def test_errors_are_one_line_exit_2(tmp_path: Path) -> None:
    broken = tmp_path / "broken.capnav"
    broken.write_bytes(b"PK\x03\x04 truncated")
    r = subprocess.run([sys.executable, "-m", "capnav.cli", "map-eval", str(broken), "--manifest",
                        str(tmp_path / "manifest.json")], capture_output=True, text=True)
    assert r.returncode == 2
    assert "error:" in r.stderr and "Traceback" not in r.stderr
    r = subprocess.run([sys.executable, "-m", "capnav.cli", "map", str(tmp_path / "nope"), "-o", str(broken)],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "dataset folder not found" in r.stderr


def test_simulator_seed_travels_with_the_map(tmp_path: Path) -> None:
    """A map of a `capnav sim` recording names its apartment, so `capnav navigate` needs no --scene."""
    from capnav.io.mapfile import load_map

    root = tmp_path / "ds"
    frames = orbit(6)
    with DatasetWriter(root, frames[0].K, {"source": "capnav.sim", "seed": 7}) as w:
        for f in frames:
            w.write(f)
    out = tmp_path / "m.capnav"
    r = CliRunner().invoke(app, ["map", str(root), "-o", str(out), "--noise", "oracle", "--no-progress"])
    assert r.exit_code == 0, r.output
    assert load_map(out).meta["scene_seed"] == 7
