"""The README's main job, end to end on a small apartment at low resolution."""

import io
from pathlib import Path

import pytest
from rich.console import Console
from typer.testing import CliRunner

from capnav.cli import app
from capnav.core.errors import InputError
from capnav.demo.report import verdict
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
    for it in res.items:  # every drive is judged for the room and the heading too, and says so
        if it.truth_distance is not None:
            assert it.in_room is not None and it.facing_deg is not None
            assert ("in its room" if it.in_room else "outside its room") in verdict(it)
    assert "stops in the object's room, facing it (truth)" in res.report_md.read_text()


def test_facing_is_the_heading_inside_the_angle_the_object_spans() -> None:
    """Facing an object means pointing at some part of it: a 2 m sofa seen from its side counts,
    a heading 90 degrees off its nearest corner does not (and says by how much)."""
    import numpy as np

    from capnav.demo.run import _off_facing_deg
    from capnav.sim.success import room_index

    sofa = np.array([[1.0, -1.0], [1.8, -1.0], [1.8, 1.0], [1.0, 1.0]])
    assert _off_facing_deg((0.0, 0.0, 0.0), sofa) == 0.0  # straight at it
    assert _off_facing_deg((0.0, 0.0, np.radians(40)), sofa) == 0.0  # at its far end: still the sofa
    assert _off_facing_deg((0.0, 0.0, np.pi), sofa) == pytest.approx(135.0)  # back to it
    assert _off_facing_deg((1.4, 0.0, 2.0), sofa) == 0.0  # standing on it
    off = _off_facing_deg((0.0, 0.0, np.radians(90)), sofa)
    assert off == pytest.approx(45.0)  # 45 degrees past the corner at (1, 1)
    rooms = [np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 3.0], [0.0, 3.0]]),
             np.array([[3.1, 0.0], [6.0, 0.0], [6.0, 3.0], [3.1, 3.0]])]
    assert [room_index(p, rooms) for p in ((1.0, 1.0), (4.0, 1.0), (3.05, 1.0))] == [0, 1, -1]


def test_demo_user_instruction_that_matches_nothing_or_is_rejected(tmp_path: Path) -> None:
    pasted = "go to the chair " * 7000  # 112 KB pasted by mistake
    con = Console(record=True, width=100, file=io.StringIO())
    res = run_demo(DemoConfig(seed=3, out=tmp_path, width=160, height=120, max_frames=60,
                              instructions=("go to the spaceship", "", pasted)), console=con)
    assert not res.items[0].found and "spaceship" in res.items[0].reason and not res.items[0].rejected
    assert verdict(res.items[0]) == "not found"
    for it in res.items[1:]:  # refused instructions say so, in the console and the report, not "not found"
        assert it.rejected and not it.found and verdict(it).startswith("rejected: ")
    assert "too long" in res.items[2].reason
    printed = con.export_text()
    assert printed.count("rejected: ") == 2 and "not found" in printed
    assert len(printed) < 5000, "the console echoed the pasted instruction"
    assert "(112,000 characters)" in printed
    html = res.report_html.read_text()
    assert "rejected: " in html and len(html) < 60_000


def test_demo_bad_arguments() -> None:
    with pytest.raises(InputError, match="seed"):
        DemoConfig(seed=-1)
    result = CliRunner().invoke(app, ["demo", "--width", "abc"])
    assert result.exit_code != 0
