"""Small things on furniture (opt-in): placed on real surfaces, in the manifest, rendered; the default
scene is untouched."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from capnav.cli import app
from capnav.eval.map_quality import inside_box
from capnav.io.dataset import DatasetReader
from capnav.sim import CameraConfig, LayoutConfig, SceneManifest, SimConfig, Simulator
from capnav.sim.apartment import generate_apartment
from capnav.sim.furniture import furnish
from capnav.sim.surface_items import ITEM_KINDS, SUPPORTS

SMALL = SimConfig(layout=LayoutConfig(rooms=3), camera=CameraConfig(width=160, height=120))


def _with_items(cfg: SimConfig, counts: tuple[int, int] = (2, 3)) -> SimConfig:
    return replace(cfg, furnish=replace(cfg.furnish, surface_items=counts))


def test_default_scene_has_no_items_and_unchanged_manifest_bytes() -> None:
    plain = furnish(generate_apartment(7, SMALL), SMALL)
    assert plain.items == [] and plain.manifest.items is None
    assert '"items"' not in plain.manifest.model_dump_json()
    cfg = _with_items(SMALL)
    rich = furnish(generate_apartment(7, cfg), cfg)
    assert rich.manifest.items
    # The furniture is drawn the same with or without the items.
    assert rich.manifest.objects == plain.manifest.objects


def test_items_stand_on_their_support_inside_its_footprint(tmp_path: Path) -> None:
    cfg = _with_items(SMALL)
    for seed in (7, 300):
        m = furnish(generate_apartment(seed, cfg), cfg).manifest
        assert m.items
        ids = {o.id for o in m.objects}
        for it in m.items:
            assert it.category in ITEM_KINDS and it.id not in ids
            sup = m.object(it.support)
            assert sup.category in SUPPORTS
            base = it.center[2] - it.size[2] / 2
            assert 0.3 <= base <= sup.size[2] + 1e-6  # on a top or a shelf of the piece
            fp = np.asarray(it.footprint)
            assert inside_box(np.c_[fp, np.full(4, sup.center[2])], sup, 1e-3).all()  # type: ignore[arg-type]
        path = tmp_path / f"m{seed}.json"
        m.save(path)
        assert SceneManifest.load(path) == m


def test_items_are_rendered_with_their_instance_ids() -> None:
    cfg = _with_items(SMALL)
    with Simulator.from_seed(7, cfg) as sim:
        it = max(sim.manifest.items or [], key=lambda i: i.size[0] * i.size[1])
        eye = np.array(it.center)
        best = 0
        for a in np.linspace(0.0, 2 * np.pi, 16, endpoint=False):
            e = np.array([it.center[0] + 0.9 * np.cos(a), it.center[1] + 0.9 * np.sin(a), 1.25])
            if sim.collides(float(e[0]), float(e[1])):
                continue
            f = e - eye
            fwd = -f / np.linalg.norm(f)
            right = np.cross(fwd, [0.0, 0.0, 1.0])
            right /= np.linalg.norm(right)
            T = np.eye(4)
            T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = right, np.cross(fwd, right), fwd, e
            frame = sim.render(T)
            assert frame.gt_instance is not None and frame.gt_category is not None
            on = frame.gt_instance == it.id
            best = max(best, int(on.sum()))
            assert not (frame.gt_category[on] > 0).any()  # no CapNav category: the sim detector ignores it
        assert best > 20


def test_cli_surface_items_flag(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    res = CliRunner().invoke(app, ["sim", "--seed", "7", "-o", str(out), "--frames", "4", "--width", "64",
                                   "--height", "48", "--rooms", "3", "--surface-items"])
    assert res.exit_code == 0, res.output
    r = DatasetReader(out)
    assert r.manifest_path is not None
    m = SceneManifest.load(r.manifest_path)
    assert m.items and all(m.object(i.support) for i in m.items)
