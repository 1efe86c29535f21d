"""The README's Python API example, run as a user would paste it (in an empty folder)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[2] / "README.md"
pytestmark = pytest.mark.slow  # explores and maps 30 frames of an apartment


def api_example() -> str:
    text = README.read_text(encoding="utf-8")
    section = text.split("## Python API", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 1, "the README's Python API section should hold exactly one python block"
    return blocks[0]


def test_readme_api_example_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys) -> None:
    monkeypatch.chdir(tmp_path)
    ns: dict[str, object] = {"__name__": "__readme__"}
    exec(compile(api_example(), str(README), "exec"), ns)
    out = capsys.readouterr().out
    assert (tmp_path / "apt0.capnav").is_file()
    answer, plan, nav = ns["answer"], ns["plan"], ns["nav"]
    assert answer.found and "armchair" in answer.object.caption.lower()  # type: ignore[attr-defined]
    assert answer.goal is not None and plan.success  # type: ignore[attr-defined]
    assert len(nav.objects()) >= 5 and answer.reason in out  # type: ignore[attr-defined]


def test_simulate_uses_the_product_pipeline(tmp_path: Path) -> None:
    from capnav.api import CapNav
    from capnav.pipeline import PipelineConfig

    cfg = PipelineConfig(width=160, height=120, max_frames=30)
    nav = CapNav.simulate(0, tmp_path, config=cfg)
    assert (tmp_path / "map.capnav").is_file() and nav.objects() and all(o.caption for o in nav.objects())
    again = CapNav.simulate(0, tmp_path, config=cfg)  # cached: the same map, not rebuilt
    assert [o.caption for o in again.objects()] == [o.caption for o in nav.objects()]
    assert nav.ask("the armchair").found
