import pytest

from capnav.core import progress


def test_plain_lines_when_not_a_terminal(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(progress, "LOG_EVERY_S", 0.0)  # a line after every item
    assert list(progress.track(range(3), "mapping")) == [0, 1, 2]
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("mapping: 1/3 in")
    assert err[-1].startswith("mapping: 3/3 in") and err[-1].endswith("done")


def test_disabled_is_silent(capsys: pytest.CaptureFixture[str]) -> None:
    assert list(progress.track(iter([5, 6]), "x", enabled=False)) == [5, 6]
    assert capsys.readouterr().err == ""
