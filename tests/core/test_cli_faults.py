"""Fault injection through the real ``capnav`` entry point, command by command: read-only outputs,
wrong kinds of path, truncated and edited inputs, NaN and out-of-range values, another apartment's
data, an interrupt. Each case must end in exit code 2 (or 1 / 130 where documented) with one
``error:`` / ``interrupted:`` line, never a traceback, and must not lose what was there."""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from _cli import cli


def refused(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, *args: str,
            says: str = "") -> str:
    code, err = cli(capsys, monkeypatch, *args)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2 and lines and lines[0].startswith("error:"), (args, code, err)
    assert says.lower() in err.lower(), (args, err)
    return err


@pytest.fixture(scope="module")
def unwritable(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """A folder this process cannot create files in: chmod 0555, or /sys for root (who ignores modes)."""
    if os.geteuid() != 0:
        d = tmp_path_factory.mktemp("ro")
        d.chmod(0o555)
        yield d
        d.chmod(0o755)
        return
    d = Path("/sys")
    try:
        (d / ".capnav-probe").write_text("x")
    except OSError:
        yield d
        return
    pytest.skip("no unwritable folder available")


@pytest.fixture(scope="module")
def data(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Two tiny apartments (seeds 0 and 1) and a map of the first, made by the commands themselves."""
    root = tmp_path_factory.mktemp("faults")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    for seed in (0, 1):
        subprocess.run([sys.executable, "-m", "capnav.cli", "sim", "-o", str(root / f"ds{seed}"), "--seed", str(seed),
                        "--frames", "6", "--width", "64", "--height", "48"], check=True, env=env,
                       capture_output=True)
    subprocess.run([sys.executable, "-m", "capnav.cli", "map", str(root / "ds0"), "-o", str(root / "m0.capnav"),
                    "--no-progress"], check=True, env=env, capture_output=True)
    return {"root": root, "ds0": root / "ds0", "ds1": root / "ds1", "map": root / "m0.capnav"}


def test_map_faults(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, data: dict[str, Path],
                    unwritable: Path, tmp_path: Path) -> None:
    ds = str(data["ds0"])
    refused(capsys, monkeypatch, "map", ds, "-o", str(unwritable / "m.capnav"), says="cannot write")
    refused(capsys, monkeypatch, "map", ds, "-o", str(tmp_path), says="is a folder")
    (tmp_path / "file").write_text("x")
    refused(capsys, monkeypatch, "map", ds, "-o", str(tmp_path / "file" / "m.capnav"), says="not a folder")
    for bad in (["--max-frames", "0"], ["--max-frames", "-5"], ["--seed", "-1"]):
        refused(capsys, monkeypatch, "map", ds, "-o", str(tmp_path / "m.capnav"), *bad, says=bad[0])
    refused(capsys, monkeypatch, "map", str(tmp_path / "nope"), "-o", str(tmp_path / "m.capnav"), says="not found")
    assert not (tmp_path / "m.capnav").exists()


def test_map_edited_dataset_skips_a_nan_pose_and_truncation_is_an_error(
        capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, data: dict[str, Path],
        tmp_path: Path) -> None:
    import shutil

    ds = tmp_path / "ds"
    shutil.copytree(data["ds0"], ds)
    lines = (ds / "poses.txt").read_text().splitlines()
    vals = lines[2].split()
    vals[5] = "nan"
    lines[2] = " ".join(vals)
    (ds / "poses.txt").write_text("\n".join(lines) + "\n")
    code, err = cli(capsys, monkeypatch, "map", str(ds), "-o", str(tmp_path / "m.capnav"), "--no-progress")
    assert code == 0 and "skipped frame 2" in err and "non-finite" in err, err
    (ds / "poses.txt").write_text("\n".join(lines)[:-40])  # truncated mid-line
    refused(capsys, monkeypatch, "map", str(ds), "-o", str(tmp_path / "m2.capnav"), says="poses.txt")


def test_map_file_is_bit_for_bit(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
                                 data: dict[str, Path], tmp_path: Path) -> None:
    code, _ = cli(capsys, monkeypatch, "map", str(data["ds0"]), "-o", str(tmp_path / "again.capnav"), "--no-progress")
    assert code == 0
    digest = [hashlib.sha256(p.read_bytes()).hexdigest() for p in (data["map"], tmp_path / "again.capnav")]
    assert digest[0] == digest[1]


def test_caption_faults(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, data: dict[str, Path],
                        unwritable: Path, tmp_path: Path) -> None:
    m = str(data["map"])
    before = data["map"].read_bytes()
    refused(capsys, monkeypatch, "caption", m, "--dataset", str(data["ds1"]), "--no-progress",
            says="is not the dataset")
    refused(capsys, monkeypatch, "caption", m, "-o", str(unwritable / "c.capnav"), says="cannot write")
    refused(capsys, monkeypatch, "caption", m, "-o", str(tmp_path), says="is a folder")
    refused(capsys, monkeypatch, "caption", m, "--embedder", "onnx", says="--embedder-path")
    refused(capsys, monkeypatch, "caption", m, "--embedder", "bge-m3", says="--embedder-path")
    refused(capsys, monkeypatch, "caption", m, "--captioner", "hf-local", says="--model-path")
    refused(capsys, monkeypatch, "caption", str(tmp_path), says="is a folder")
    assert data["map"].read_bytes() == before


def test_map_eval_and_query_faults(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
                                   data: dict[str, Path], unwritable: Path, tmp_path: Path) -> None:
    from capnav.io.mapfile import load_map, save_map

    m = str(data["map"])
    refused(capsys, monkeypatch, "map-eval", m, "--manifest", str(data["ds1"] / "manifest.json"),
            says="apartment 1")
    refused(capsys, monkeypatch, "map-eval", m, "--manifest", str(data["ds0"] / "manifest.json"), "--json",
            str(unwritable / "q.json"), says="cannot write")
    refused(capsys, monkeypatch, "query", m, "sofa", "--verifier", "bogus", says="unknown verifier")
    refused(capsys, monkeypatch, "query", m, "sofa", "--verifier", "hf-local", says="model folder")
    cmap = load_map(data["map"])
    assert len(cmap.voxels) > 0
    cmap.voxels.weights[0] = np.nan  # a view into the map's own array
    if cmap.objects:
        cmap.objects[0].position = np.full(3, np.nan)
    save_map(cmap, tmp_path / "nan.capnav")  # checksums are right, the values are not
    refused(capsys, monkeypatch, "query", str(tmp_path / "nan.capnav"), "sofa", says="NaN")
    (tmp_path / "cut.capnav").write_bytes(data["map"].read_bytes()[:5000])
    refused(capsys, monkeypatch, "query", str(tmp_path / "cut.capnav"), "sofa", says="truncated")


def test_navigate_faults(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
                         data: dict[str, Path], tmp_path: Path) -> None:
    m = str(data["map"])
    refused(capsys, monkeypatch, "navigate", m, "sofa", "--scene", "5", "-o", str(tmp_path / "n"),
            says="apartment 0")
    (tmp_path / "file").write_text("x")
    refused(capsys, monkeypatch, "navigate", m, "sofa", "-o", str(tmp_path / "file"), says="is a file")
    refused(capsys, monkeypatch, "navigate", m, "sofa", "-o", str(tmp_path / "n"), "--verifier", "nope",
            says="unknown verifier")


def test_sim_eval_demo_import_faults(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
                                     unwritable: Path, tmp_path: Path, data: dict[str, Path]) -> None:
    (tmp_path / "file").write_text("x")
    refused(capsys, monkeypatch, "sim", "-o", str(unwritable / "ds"), says="cannot write")
    refused(capsys, monkeypatch, "sim", "-o", str(tmp_path / "file"), says="is a file")
    refused(capsys, monkeypatch, "sim", "-o", str(data["ds0"]), says="--overwrite")
    for bad in (["--frames", "0"], ["--seed", "-1"], ["--width", "8"], ["--rooms", "12"]):
        refused(capsys, monkeypatch, "sim", "-o", str(tmp_path / "ds"), *bad, says=bad[0])
    for bad in (["--scenes", "0"], ["--scenes", "-2"], ["--max-steps", "-5"], ["--seed", "-1"], ["--workers", "0"],
                ["--episodes-per-scene", "0"], ["--max-frames", "0"]):
        refused(capsys, monkeypatch, "eval", "-o", str(tmp_path / "run"), *bad, says=bad[0])
    refused(capsys, monkeypatch, "eval", "-o", str(tmp_path / "file"), says="is a file")
    refused(capsys, monkeypatch, "demo", "--out", str(tmp_path / "file"), says="is a file")
    refused(capsys, monkeypatch, "demo", "--out", str(unwritable / "d"), says="cannot write")
    refused(capsys, monkeypatch, "demo", "--out", str(tmp_path / "d"), "--verifier", "bogus", says="unknown verifier")
    refused(capsys, monkeypatch, "demo", "--out", str(tmp_path / "d"), "--width", "5000", says="--width")
    refused(capsys, monkeypatch, "import", "tum", str(tmp_path), "-o", str(unwritable / "t"), says="cannot write")
    refused(capsys, monkeypatch, "import", "tum", str(tmp_path), "-o", str(tmp_path / "t"), "--stride", "0",
            says="--stride")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]  # nothing was started


def test_interrupted_sim_overwrite_keeps_the_old_dataset_and_stops_fast(data: dict[str, Path],
                                                                        tmp_path: Path) -> None:
    import shutil

    ds = tmp_path / "ds"
    shutil.copytree(data["ds1"], ds)
    before = {p.relative_to(ds): p.read_bytes() for p in ds.rglob("*") if p.is_file()}
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    proc = subprocess.Popen([sys.executable, "-m", "capnav.cli", "sim", "-o", str(ds), "--overwrite", "--seed", "0",
                             "--frames", "400", "--width", "64", "--height", "48"], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            # SIGINT as a terminal delivers it, even when this test runs in the
                            # background of a non-interactive shell (which starts it ignored).
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 120
    while not any(p.name.startswith(".ds.tmp-") and (p / "rgb").is_dir() and any((p / "rgb").iterdir())
                  for p in tmp_path.iterdir()):
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.05)
    t0 = time.monotonic()
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=30)
    stopped = time.monotonic() - t0
    assert proc.returncode == 130 and "interrupted:" in err and "left as it was" in err, err
    assert "Traceback" not in err
    assert stopped < 20.0, stopped  # a generous bound (a loaded machine): it stops, it does not finish the 400 frames
    after = {p.relative_to(ds): p.read_bytes() for p in ds.rglob("*") if p.is_file()}
    assert after == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ds"]
