"""``capnav sim --export LAYOUT --tilt R,P,Y``: the same exploration pass written in another tool's layout, in
a tilted world, read back by ``capnav import auto`` with no option: the cameras' heights and their motion
relative to each other are the simulator's."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from capnav.cli import app
from capnav.core.errors import InputError
from capnav.io.dataset import DatasetReader
from capnav.io.layouts import detect

SIM = ["sim", "--seed", "0", "--rooms", "3", "--frames", "10", "--stride", "4", "--width", "96", "--height", "72"]


@pytest.fixture(scope="module")
def plain(tmp_path_factory: pytest.TempPathFactory) -> DatasetReader:
    out = tmp_path_factory.mktemp("plain") / "ds"
    res = CliRunner().invoke(app, [*SIM, "-o", str(out)])
    assert res.exit_code == 0, res.output
    return DatasetReader(out)


@pytest.mark.parametrize("layout", ["tum", "open3d", "3dmatch", "scannet"])
def test_export_reads_back(tmp_path: Path, plain: DatasetReader, layout: str) -> None:
    rec = tmp_path / "rec"
    res = CliRunner().invoke(app, [*SIM, "--export", layout, "--tilt", "10,-20,30", "-o", str(rec)])
    assert res.exit_code == 0, res.output
    assert detect(rec)[0].name == layout and (rec / "manifest.json").is_file()
    res = CliRunner().invoke(app, ["import", "auto", str(rec), "-o", str(tmp_path / "ds"), "--no-progress"])
    assert res.exit_code == 0, res.output + repr(res.exception)
    assert f"{layout} layout" in res.output and "poses checked against depth" in res.output
    ds = DatasetReader(tmp_path / "ds")
    assert len(ds) == len(plain)
    assert np.abs(ds.poses[:, 2, 3] - plain.poses[:, 2, 3]).max() < 0.01  # heights above the floor
    for i in range(1, len(ds)):  # motion between frames: the same, whatever the world's yaw and origin
        rel_a = np.linalg.inv(ds.poses[0]) @ ds.poses[i]
        rel_b = np.linalg.inv(plain.poses[0]) @ plain.poses[i]
        assert np.abs(rel_a - rel_b).max() < 0.01
    K, Kp = ds.intrinsics, plain.intrinsics
    assert np.allclose([K.fx, K.fy, K.cx, K.cy], [Kp.fx, Kp.fy, Kp.cx, Kp.cy], atol=1e-4)


def test_export_options_checked(tmp_path: Path) -> None:
    res = CliRunner().invoke(app, [*SIM, "--export", "kitti", "-o", str(tmp_path / "a")])
    assert isinstance(res.exception, InputError) and "--export must be one of tum, open3d" in str(res.exception)
    res = CliRunner().invoke(app, [*SIM, "--tilt", "1,2,3", "-o", str(tmp_path / "b")])
    assert isinstance(res.exception, InputError) and "give --export too" in str(res.exception)
    res = CliRunner().invoke(app, [*SIM, "--export", "tum", "--tilt", "1,2", "-o", str(tmp_path / "c")])
    assert isinstance(res.exception, InputError) and "--tilt must be three" in str(res.exception)
