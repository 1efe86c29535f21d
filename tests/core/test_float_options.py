"""Every float option of ``capnav import``, ``serve`` and ``view`` refuses NaN and infinity (which
a range check alone lets through: every comparison with NaN is false) in one line naming the
option, before any file is opened; a value in range still reaches the command."""

from __future__ import annotations

from pathlib import Path

import pytest
from _cli import cli

CASES = [
    (["import", "tum", "{src}", "-o", "{out}"], "--depth-scale"),
    (["import", "tum", "{src}", "-o", "{out}"], "--max-dt"),
    (["import", "tum", "{src}", "-o", "{out}"], "--max-pose-gap"),
    (["import", "open3d", "{src}", "-o", "{out}"], "--fps"),
    (["import", "open3d", "{src}", "-o", "{out}"], "--depth-scale"),
    (["serve", "{map}"], "--time-limit"),
    (["serve", "{map}"], "--body-timeout"),
    (["serve", "{map}"], "--header-timeout"),
    (["serve", "{map}"], "--rate"),
    (["view", "{map}", "-o", "{out}.rrd"], "--max-z"),
]


def _args(tmp_path: Path, words: list[str]) -> list[str]:
    paths = {"src": str(tmp_path / "rec"), "out": str(tmp_path / "out"), "map": str(tmp_path / "home.capnav")}
    return [w.format(**paths) for w in words]


@pytest.mark.parametrize(("value", "says"), [("nan", "is not a number"), ("inf", "not a finite number"),
                                             ("-inf", "not a finite number")])
@pytest.mark.parametrize(("words", "option"), CASES, ids=[f"{w[0]}-{o}" for w, o in CASES])
def test_non_finite_floats_are_refused_naming_the_option(capsys: pytest.CaptureFixture[str],
                                                         monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
                                                         words: list[str], option: str, value: str, says: str) -> None:
    code, err = cli(capsys, monkeypatch, *_args(tmp_path, words), option, value)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2 and len(lines) == 1, err
    assert lines[0].startswith("error:") and option in lines[0] and says in lines[0]
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(("words", "option", "value"), [
    (["serve", "{map}"], "--time-limit", "0.001"), (["import", "tum", "{src}", "-o", "{out}"], "--depth-scale", "0"),
    (["import", "open3d", "{src}", "-o", "{out}"], "--fps", "-30"), (["serve", "{map}"], "--rate", "-1")])
def test_out_of_range_floats_say_the_range(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
                                           tmp_path: Path, words: list[str], option: str, value: str) -> None:
    code, err = cli(capsys, monkeypatch, *_args(tmp_path, words), option, value)
    assert code == 2 and option in err and "out of range; give a number >=" in err


@pytest.mark.parametrize(("words", "option", "value"), [
    (["serve", "{map}"], "--time-limit", "2.5"), (["view", "{map}", "-o", "{out}.rrd"], "--max-z", "2.0"),
    (["import", "tum", "{src}", "-o", "{out}"], "--depth-scale", "1000")])
def test_a_finite_value_reaches_the_command(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
                                            tmp_path: Path, words: list[str], option: str, value: str) -> None:
    code, err = cli(capsys, monkeypatch, *_args(tmp_path, words), option, value)
    assert code != 0 and option not in err and "not found" in err  # past the option: the missing input is named
