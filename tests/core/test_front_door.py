"""What a newcomer meets first: messages that name the real problem (a folder given for a map, NaN
for a number, the field a manifest lacks), install hints that name this environment's pip, console
lines that piping does not break, a .gitignore that keeps outputs out of git, and the README's test
command being the one CI runs."""

from __future__ import annotations

import io
import json
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
from _cli import cli

REPO = Path(__file__).resolve().parents[2]




def one_error(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, *args: str) -> str:
    code, err = cli(capsys, monkeypatch, *args)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2 and len(lines) == 1 and lines[0].startswith("error:"), (args, code, err)
    return lines[0]


def test_a_folder_given_as_a_map_is_called_a_folder(capsys: pytest.CaptureFixture[str],
                                                    monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "map.capnav").write_bytes(b"x")
    msg = one_error(capsys, monkeypatch, "query", str(tmp_path / "run"), "the chair")
    assert "is a folder, not a map file" in msg and "map.capnav" in msg and "not found" not in msg
    msg = one_error(capsys, monkeypatch, "query", str(tmp_path), "the chair")
    assert "is a folder" in msg
    assert "not found" in one_error(capsys, monkeypatch, "query", str(tmp_path / "nope.capnav"), "the chair")


@pytest.mark.parametrize(("value", "says"), [("nan", "is not a number"), ("NaN", "is not a number"),
                                             ("inf", "not a finite number"), ("-inf", "not a finite number"),
                                             ("ten", "is not a number"), ("200", "between 10 and 150"),
                                             ("9.5", "between 10 and 150")])
def test_hfov_says_what_is_wrong(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
                                 tmp_path: Path, value: str, says: str) -> None:
    msg = one_error(capsys, monkeypatch, "sim", "-o", str(tmp_path / "ds"), "--hfov", value)
    assert says in msg and "--hfov" in msg
    assert not (tmp_path / "ds").exists()


def test_finite_float_accepts_the_range_ends() -> None:
    from capnav.cli.options import finite_float

    parse = finite_float(10, 150)
    assert parse("10") == 10.0 and parse("150") == 150.0 and parse(" 90.5 ") == 90.5


def test_an_incomplete_manifest_names_the_missing_field_in_one_line(tmp_path: Path) -> None:
    from capnav.core.errors import DatasetError
    from capnav.sim import Simulator
    from capnav.sim.config import SimConfig
    from capnav.sim.manifest import SceneManifest

    with Simulator.from_seed(1, SimConfig()) as sim:
        data = json.loads(sim.manifest.model_dump_json())
    del data["objects"][2]["category"]
    p = tmp_path / "manifest.json"
    p.write_text(json.dumps(data))
    with pytest.raises(DatasetError) as e:
        SceneManifest.load(p)
    msg = str(e.value)
    assert "\n" not in msg and "objects[2].category is missing" in msg and "http" not in msg
    data["objects"][0]["yaw"] = "here"
    del data["rooms"]
    p.write_text(json.dumps(data))
    with pytest.raises(DatasetError, match=r"rooms is missing \(and 2 more problems\)$"):
        SceneManifest.load(p)


def test_install_hints_name_this_interpreters_pip(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    from capnav.core.errors import pip_hint

    hint = pip_hint("capnav[serve]")
    words = shlex.split(hint)
    assert Path(words[0]).resolve() == Path(sys.executable).resolve() and words[1:4] == ["-m", "pip", "install"]
    if (REPO / "pyproject.toml").is_file():  # a checkout: its editable install, not a package index's
        assert words[4] == "-e" and Path(words[5].removesuffix("[serve]")).resolve() == REPO
    monkeypatch.chdir(tmp_path)
    assert shlex.split(pip_hint("opencv-python-headless<5"))[-1] == "opencv-python-headless<5"
    # the messages that need an extra use it (no bare "pip install" left in the package's messages)
    bare = [f"{p.relative_to(REPO)}:{i}" for p in (REPO / "src" / "capnav").rglob("*.py")
            for i, ln in enumerate(p.read_text().splitlines(), 1)
            if re.search(r"""["'][^"'`]*(?<!-m )\bpip install""", ln) and "pip_hint" not in ln and "``" not in ln]
    assert bare == []


def test_piped_console_lines_are_not_wrapped(monkeypatch: pytest.MonkeyPatch) -> None:
    from capnav.core.console import make_console

    monkeypatch.delenv("COLUMNS", raising=False)
    buf = io.StringIO()
    monkeypatch.setattr(sys, "stdout", buf)
    long = "wrote 231 frames of apartment seed 0 to " + "/very/long/path" * 12
    make_console().print(long, markup=False, highlight=False)
    assert buf.getvalue() == long + "\n"


def test_the_map_command_prints_its_summary_on_one_line_when_piped(tmp_path: Path) -> None:
    env = {"PYTHONPATH": str(REPO / "src"), "PATH": "/usr/bin:/bin"}
    deep = tmp_path / ("a-rather-long-folder-name-" * 3) / "ds"
    r = subprocess.run([sys.executable, "-m", "capnav.cli", "sim", "-o", str(deep), "--frames", "4", "--width", "32",
                        "--height", "24"], env=env, capture_output=True, text=True, check=True)
    line = next(ln for ln in r.stdout.splitlines() if ln.startswith("wrote "))
    assert str(deep) in line


def test_gitignore_keeps_outputs_out_of_git(tmp_path: Path) -> None:
    if not (REPO / ".git").exists():
        pytest.skip("not a git checkout")
    probes = ["data/apt3/rgb/000000.png", "runs/demo/report.html", "apt3.capnav", "sub/room.capnav", "apt3.rrd",
              ".venv/bin/python"]
    r = subprocess.run(["git", "-C", str(REPO), "check-ignore", "--no-index", *probes], capture_output=True, text=True)
    assert sorted(r.stdout.split()) == sorted(probes)


def test_the_readme_test_command_is_the_one_ci_runs() -> None:
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    cmd = re.search(r"\.venv/bin/python -m pytest([^\n#]*)", readme)
    assert cmd is not None, "the README shows no test command"
    args = cmd.group(1).split()
    assert "-rs" in args, "the README's test command should show why tests skip (-rs)"
    ci = (REPO / ".ci" / "run").read_text(encoding="utf-8")
    ran = re.search(r'bin/python" -m pytest([^\n#]*)', ci)
    assert ran is not None and set(args) <= set(ran.group(1).split())
