"""``capnav models``: install from a local folder (../shared/weights) or from URLs (file:// URLs here,
never the network), checksums, the licence record, listing, and what a detector finds afterwards."""

from __future__ import annotations

import dataclasses
import json
import os
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from capnav.cli import app
from capnav.core.errors import InputError, ModelError
from capnav.perception import create_detector
from capnav.perception import model_store as ms


def _weights(shared_dir: Path, name: str) -> Path:
    return shared_dir / "weights" / ("yolo-fastest-1.1-xl" if name.startswith("yolo") else name)


@pytest.mark.parametrize("name", list(ms.MODELS))
def test_install_from_folder_and_list(name: str, shared_dir: Path, tmp_path: Path) -> None:
    out = ms.install(name, root=tmp_path, source_dir=_weights(shared_dir, name))
    assert out == tmp_path / name
    rec = json.loads((out / ms.RECORD).read_text())
    assert rec["name"] == name and rec["licence"] == ms.MODELS[name].licence and rec["source"]
    for f in ms.MODELS[name].files:
        assert ms.sha256_file(out / f.name) == f.sha256 == rec["files"][f.name]["sha256"]
    assert (out / f.name).stat().st_mode & 0o044  # readable by others, like any cache
    rows = {r["name"]: r for r in ms.installed(tmp_path)}
    assert rows[name]["status"] == "ok"
    assert all(r["status"] == "not installed" for n, r in rows.items() if n != name)
    assert ms.locate(name, root=tmp_path) == out


def test_install_from_a_folder_of_models(shared_dir: Path, tmp_path: Path) -> None:
    """``--from ../shared/weights`` (one subfolder per model) finds the model's own subfolder."""
    name = "centernet-mobilenetv3-coco"
    out = ms.install(name, root=tmp_path, source_dir=shared_dir / "weights")
    assert ms.locate(name, root=tmp_path) == out
    with pytest.raises(ModelError, match="is missing"):  # a folder with neither the files nor a subfolder
        ms.install(name, root=tmp_path, source_dir=shared_dir / "realdata")


def test_detector_finds_the_installed_model(shared_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CAPNAV_MODELS", str(tmp_path))
    r = CliRunner().invoke(app, ["models", "install", "yolo-fastest-1.1-xl", "--from",
                                 str(shared_dir / "weights" / "yolo-fastest-1.1-xl")])
    assert r.exit_code == 0, r.output
    assert "installed in" in r.output and "public domain" in r.output
    det = create_detector("yolo-fastest")
    assert det.folder == tmp_path / "yolo-fastest-1.1-xl"
    r = CliRunner().invoke(app, ["models", "list"])
    assert r.exit_code == 0 and "yolo-fastest-1.1-xl" in r.output and "not installed" in r.output


def test_corrupt_source_is_refused_and_keeps_the_old_copy(shared_dir: Path, tmp_path: Path) -> None:
    name = "centernet-mobilenetv3-coco"
    good = ms.install(name, root=tmp_path / "models", source_dir=_weights(shared_dir, name))
    bad = tmp_path / "bad"
    shutil.copytree(_weights(shared_dir, name), bad)
    onnx = bad / "centernet.onnx"
    onnx.chmod(0o644)
    onnx.write_bytes(onnx.read_bytes()[:100_000])  # a truncated ONNX
    with pytest.raises(ModelError, match=r"centernet.onnx has sha256 .*truncated"):
        ms.install(name, root=tmp_path / "models", source_dir=bad)
    assert ms.sha256_file(good / "centernet.onnx") == ms.MODELS[name].files[0].sha256
    assert sorted(p.name for p in (tmp_path / "models").iterdir()) == [name]  # no half install left
    (bad / "LICENSE-human-models-MIT.txt").unlink()
    with pytest.raises(ModelError, match=r"LICENSE-human-models-MIT\.txt is missing"):
        ms.install(name, root=tmp_path / "models", source_dir=bad)
    # a broken installed copy shows in the list and is refused by the detector with the reinstall command
    (good / "centernet.onnx").write_bytes(b"not an onnx file")
    assert ms.installed(tmp_path / "models")[-1]["status"].startswith("broken")
    with pytest.raises(ModelError, match=f"capnav models install {name}"):
        ms.locate(name, root=tmp_path / "models")


def test_cli_errors_are_one_line(tmp_path: Path) -> None:
    r = CliRunner().invoke(app, ["models", "install", "centernet-mobilenetv3-coco", "--dir", str(tmp_path)])
    assert isinstance(r.exception, InputError) and "--from" in str(r.exception) and "tf2onnx" in str(r.exception)
    r = CliRunner().invoke(app, ["models", "install", "yolo-v9", "--dir", str(tmp_path)])
    assert isinstance(r.exception, InputError) and "known: yolo-fastest-1.1-xl" in str(r.exception)
    r = CliRunner().invoke(app, ["models", "install", "yolo-fastest-1.1", "--from", str(tmp_path / "x")])
    assert isinstance(r.exception, InputError) and "not an existing folder" in str(r.exception)
    (tmp_path / "file").write_text("x")
    r = CliRunner().invoke(app, ["models", "install", "yolo-fastest-1.1", "--from", str(tmp_path),
                                 "--dir", str(tmp_path / "file")])
    assert isinstance(r.exception, InputError) and "cannot use" in str(r.exception)


def test_install_from_urls(shared_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The download path, fed file:// URLs of the shared copy (tests never touch the network)."""
    name = "yolo-fastest-1.1"
    src = _weights(shared_dir, name)
    s = ms.MODELS[name]
    assert s.downloadable and all(f.url and f.url.startswith("https://") for f in s.files)
    local = dataclasses.replace(s, files=tuple(dataclasses.replace(f, url=(src / f.name).as_uri()) for f in s.files))
    monkeypatch.setitem(ms.MODELS, name, local)
    out = ms.install(name, root=tmp_path)
    assert json.loads((out / ms.RECORD).read_text())["installed_from"] == "public source URLs"
    wrong = dataclasses.replace(local, files=(dataclasses.replace(local.files[0], url=(src / "LICENSE").as_uri()),
                                              *local.files[1:]))
    monkeypatch.setitem(ms.MODELS, name, wrong)
    with pytest.raises(ModelError, match="sha256"):
        ms.install(name, root=tmp_path)
    gone = dataclasses.replace(local, files=(dataclasses.replace(local.files[0], url=(tmp_path / "no").as_uri()),))
    monkeypatch.setitem(ms.MODELS, name, gone)
    with pytest.raises(ModelError, match="cannot download"):
        ms.install(name, root=tmp_path)


def test_install_follows_the_umask(shared_dir: Path, tmp_path: Path) -> None:
    name = "yolo-fastest-1.1-xl"
    old = os.umask(0o077)
    try:
        out = ms.install(name, root=tmp_path, source_dir=_weights(shared_dir, name))
    finally:
        os.umask(old)
    assert out.stat().st_mode & 0o777 == 0o700
    assert {p.stat().st_mode & 0o777 for p in out.iterdir()} == {0o600}
    assert not (out / ".capnav-install-pid").exists()


def test_next_install_removes_what_a_killed_one_left(shared_dir: Path, tmp_path: Path) -> None:
    """A temporary folder whose install process is gone (SIGKILL) is removed by the next install;
    one whose process still runs (a concurrent install) is left alone."""
    import subprocess
    import sys

    name = "yolo-fastest-1.1-xl"
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    gone = tmp_path / f".{name}.killed1"
    gone.mkdir()
    (gone / ".capnav-install-pid").write_text(dead.stdout.strip())
    (gone / f"{name}.weights").write_bytes(b"half a file")
    running = tmp_path / f".{name}.running"
    running.mkdir()
    (running / ".capnav-install-pid").write_text(str(os.getppid()))  # alive: the test runner's parent
    other = tmp_path / ".yolo-fastest-1.1.killed"  # another model's: not this install's to judge
    other.mkdir()
    ms.install(name, root=tmp_path, source_dir=_weights(shared_dir, name))
    assert not gone.exists() and running.exists() and other.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([name, running.name, other.name])


def test_models_install_errors_are_one_line(shared_dir: Path, tmp_path: Path) -> None:
    import subprocess
    import sys

    src = str(_weights(shared_dir, "yolo-fastest-1.1-xl"))
    for args in (["nope"], ["yolo-fastest-1.1-xl", "--from", str(tmp_path / "none")],
                 ["yolo-fastest-1.1-xl", "--from", src, "--dir", "/sys/capnav-models"],
                 ["yolo-fastest-1.1-xl", "--from", str(tmp_path)]):
        r = subprocess.run([sys.executable, "-m", "capnav.cli", "models", "install", *args], capture_output=True,
                           text=True, timeout=120)
        assert r.returncode == 2 and r.stderr.startswith("error: "), (args, r.stderr)
        assert len(r.stderr.strip().splitlines()) == 1, r.stderr
