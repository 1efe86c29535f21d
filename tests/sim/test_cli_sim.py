"""``capnav sim`` end to end on a tiny apartment, and its bad-input errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from capnav.cli import app
from capnav.io.dataset import DatasetReader
from capnav.sim import SceneManifest


def test_sim_command_writes_dataset_manifest_and_picture(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    res = CliRunner().invoke(app, ["sim", "--seed", "2", "-o", str(out), "--frames", "8", "--width", "64",
                                   "--height", "48", "--rooms", "3"])
    assert res.exit_code == 0, res.output
    r = DatasetReader(out)
    assert len(r) == 8 and r.intrinsics.width == 64
    assert r.manifest_path is not None
    m = SceneManifest.load(r.manifest_path)
    assert m.seed == 2 and len(m.rooms) == 3
    ids = set().union(*(np.unique(f.gt_instance).tolist() for f in r))
    assert ids - {0} <= {o.id for o in m.objects}
    assert (out / "topdown.png").stat().st_size > 1000


def test_sim_command_bad_input(tmp_path: Path) -> None:
    from capnav.core.errors import CapNavError

    runner = CliRunner()
    for args in (["--seed", "-3"], ["--width", "2"], ["--rooms", "12"], ["--frames", "0"]):
        res = runner.invoke(app, ["sim", "-o", str(tmp_path / "x"), *args])
        assert res.exit_code == 2 and args[0] in res.output, (args, res.output)  # refused by the shared limits
    f = tmp_path / "file"
    f.write_text("x")
    res = runner.invoke(app, ["sim", "-o", str(f), "--frames", "2"])
    assert isinstance(res.exception, CapNavError)
