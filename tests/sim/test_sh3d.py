"""Sweet Home 3D meshes: catalog parsing, per-material OBJ split, and a full offline `capnav assets` run
on a small .deb built here (the real package is never downloaded in tests)."""

from __future__ import annotations

import shutil
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest

from capnav.core.errors import DatasetError
from capnav.sim import LayoutConfig, SimConfig, Simulator
from capnav.sim.sh3d import load_catalog, map_category, parse_properties, read_obj, split_model

# A two-material box (SH3D axes: y up, front towards +z): a red seat and a blue back.
OBJ = """mtllib m.mtl
v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nv -1 1 -1\nv 1 1 -1\nv 1 1 1\nv -1 1 1
v -1 1 -1\nv 1 1 -1\nv 1 3 -1\nv -1 3 -1
usemtl seat
f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1
usemtl back
f 9 10 11 12
"""
MTL = "newmtl seat\nKd 0.8 0.1 0.1\nnewmtl back\nKd 0.1 0.1 0.9\n"
PROPS = """# test catalog
id=Test
name=Test catalog
license=Public domain
id#1=Test#chair1
name#1=Chair
category#1=Kitchen
model#1=/test/chair1/chair1.obj
width#1=50
depth#1=50
height#1=90
doorOrWindow#1=false
creator#1=Someone \\u00e9
id#2=Test#window
name#2=Window
category#2=Doors and windows
model#2=/test/window/w.obj
width#2=100
depth#2=10
height#2=120
doorOrWindow#2=true
"""


def test_category_mapping() -> None:
    assert map_category("Corner sofa") == "sofa"
    assert map_category("Modern armchair") == "armchair"
    assert map_category("Bar stool") == "stool"
    assert map_category("Coffee table") == "coffee table"
    assert map_category("Round table") == "table"
    assert map_category("Washing machine") == "washing machine"
    assert map_category("Table tennis bat") is None
    assert map_category("Desk lamp") is None
    assert map_category("Radiator") is None


def test_properties_parsing() -> None:
    p = parse_properties(PROPS)
    assert p["name#1"] == "Chair" and p["creator#1"] == "Someone é" and p["width#1"] == "50"


def test_split_per_material_keeps_colours_and_normalises(tmp_path: Path) -> None:
    (tmp_path / "c.obj").write_text(OBJ)
    (tmp_path / "m.mtl").write_text(MTL)
    mesh = read_obj(tmp_path / "c.obj")
    assert [m for m, _ in mesh.faces] == ["seat", "back"]
    parts = split_model(tmp_path / "c.obj", tmp_path / "out", None)
    assert [p["rgba"][:3] for p in parts] == [[0.8, 0.1, 0.1], [0.1, 0.1, 0.9]]
    allv = np.concatenate([read_obj(tmp_path / "out" / p["obj"]).vertices for p in parts])
    np.testing.assert_allclose(allv.min(axis=0), [-0.5, -0.5, 0.0], atol=1e-6)
    np.testing.assert_allclose(allv.max(axis=0), [0.5, 0.5, 1.0], atol=1e-6)
    back = read_obj(tmp_path / "out" / parts[1]["obj"]).vertices
    assert np.allclose(back[:, 1], -0.5)  # SH3D's back (-z) lands at CapNav's back (-y)
    assert back[:, 2].max() == pytest.approx(1.0)  # SH3D's up (+y) is CapNav's up (+z)


@pytest.mark.skipif(shutil.which("dpkg-deb") is None, reason="needs dpkg-deb")
def test_assets_from_a_local_deb_and_render(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from capnav.cli import app

    sh3f = tmp_path / "pkg" / "usr" / "share" / "sweethome3d" / "furniture" / "Test.sh3f"
    sh3f.parent.mkdir(parents=True)
    with zipfile.ZipFile(sh3f, "w") as z:
        z.writestr("PluginFurnitureCatalog.properties", PROPS)
        z.writestr("test/chair1/chair1.obj", OBJ)
        z.writestr("test/chair1/m.mtl", MTL)
    (tmp_path / "pkg" / "DEBIAN").mkdir()
    (tmp_path / "pkg" / "DEBIAN" / "control").write_text(
        "Package: sweethome3d-furniture\nVersion: 0.0-test\nArchitecture: all\nMaintainer: t <t@t>\nDescription: t\n")
    deb = tmp_path / "f.deb"
    subprocess.run(["dpkg-deb", "--build", str(tmp_path / "pkg"), str(deb)], check=True, capture_output=True)
    cache = tmp_path / "cache"
    res = CliRunner().invoke(app, ["assets", "--dir", str(cache), "--deb", str(deb)])
    assert res.exit_code == 0, res.output
    models = load_catalog(cache)
    assert [(m.name, m.category, m.size) for m in models] == [("Chair", "chair", (0.5, 0.5, 0.9))]
    assert not (cache / "raw").exists()
    cfg = SimConfig(layout=LayoutConfig(rooms=4), furniture="sh3d", assets_dir=str(cache))
    with Simulator.from_seed(1, cfg) as sim:
        chairs = sim.manifest.by_category("chair")
        assert chairs and all(o.model == "sh3d:Test#chair1" and o.color_name == "red" for o in chairs)
        c = chairs[0]
        # look at the chair from the navigable point nearest to 1.2 m in front of it: its pixels carry its id
        from capnav.core.geometry import look_at_pose

        pts = sim.nav_grid().free_points()
        d = np.abs(np.hypot(pts[:, 0] - c.center[0], pts[:, 1] - c.center[1]) - 1.2)
        x, y = pts[int(np.argmin(d))]
        T = look_at_pose(np.array([x, y, 1.25]), float(np.arctan2(c.center[1] - y, c.center[0] - x)), 0.5)
        f = sim.render(T)
        assert (f.gt_instance == c.id).sum() > 50
    with pytest.raises(DatasetError, match="capnav assets"):
        Simulator.from_seed(1, SimConfig(furniture="sh3d", assets_dir=str(tmp_path / "none")))
