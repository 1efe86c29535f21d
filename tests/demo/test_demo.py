"""The README's main job, end to end on a small apartment at low resolution."""

from pathlib import Path

import pytest
from typer.testing import CliRunner

from capnav.cli import app
from capnav.core.errors import InputError
from capnav.demo.run import DemoConfig, run_demo


def test_demo_runs_the_whole_loop(tmp_path: Path) -> None:
    res = run_demo(DemoConfig(seed=3, out=tmp_path, width=160, height=120, max_frames=120,
                              kinds=("attribute", "category", "absent")))
    html = res.report_html.read_text()
    assert res.report_md.is_file() and (tmp_path / "map.capnav").is_file()
    assert len(res.items) == 3
    kinds = [it.kind for it in res.items]
    assert kinds == ["attribute", "category", "absent"]
    found = [it for it in res.items if it.found]
    assert found, "the demo answered nothing"
    for it in found:  # every answer is explained and drawn
        assert it.reason and it.caption and it.map_png
        assert (tmp_path / it.map_png).stat().st_size > 1000
        assert it.map_png in html
    # the absent category must not be "found" by construction of a good retriever; judged by truth
    absent = res.items[2]
    assert absent.correct is not None
    assert "CapNav demo" in html
    # one id per object: the overview is the map (map ids, as in the answers); the truth picture says it is truth
    assert (tmp_path / "images" / "map.png").stat().st_size > 1000 and "images/map.png" in html
    assert "T-numbers are truth ids, not map ids" in html and "images/apartment.png" in html


def test_demo_user_instruction_that_matches_nothing(tmp_path: Path) -> None:
    res = run_demo(DemoConfig(seed=3, out=tmp_path, width=160, height=120, max_frames=60,
                              instructions=("go to the spaceship", "")))
    assert not res.items[0].found and "spaceship" in res.items[0].reason
    assert not res.items[1].found and res.items[1].reason.startswith("rejected")


def test_demo_bad_arguments() -> None:
    with pytest.raises(InputError, match="seed"):
        DemoConfig(seed=-1)
    result = CliRunner().invoke(app, ["demo", "--width", "abc"])
    assert result.exit_code != 0
