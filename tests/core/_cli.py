"""Running ``capnav ARGS`` in the test's own process, shared by the CLI tests of this folder."""

from __future__ import annotations

import sys

import pytest

from capnav.cli import main


def cli(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, *args: str) -> tuple[int, str]:
    """Run ``capnav ARGS`` in this process through ``main()``; return (exit code, stderr)."""
    monkeypatch.setattr(sys, "argv", ["capnav", *args])
    capsys.readouterr()
    with pytest.raises(SystemExit) as ex:
        main()
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    return int(ex.value.code or 0), err
