"""The README's command blocks marked ``<!-- quick -->``, run line by line as a reader would paste
them into a new shell in an empty folder: every line must succeed (exit 0) in order, and the files
the later lines read must be the ones the earlier lines wrote. ``.venv/bin/capnav`` is this
interpreter's CapNav. The demo is not among them (it is the README's first command and has its own
test, tests/demo); nothing is downloaded: the detector weights come from the shared folder.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
README = REPO / "README.md"
pytestmark = pytest.mark.slow  # each block maps a small apartment (a few minutes on two cores)


def quick_blocks() -> list[list[str]]:
    """The command lines of every ```bash block right after a ``<!-- quick -->`` line."""
    text = README.read_text(encoding="utf-8")
    blocks = re.findall(r"<!-- quick -->\s*\n```bash\n(.*?)```", text, flags=re.S)
    out = []
    for b in blocks:
        lines = [ln.split(" # ", 1)[0].rstrip() for ln in b.splitlines()]
        out.append([ln for ln in lines if ln.strip() and not ln.lstrip().startswith("#")])
    return out


def test_the_readme_marks_its_quick_blocks() -> None:
    blocks = quick_blocks()
    assert len(blocks) >= 2, "the tour and the own-recording walk-through should be marked <!-- quick -->"
    assert any("--export tum" in ln for b in blocks for ln in b)
    assert any(ln.split()[1:3] == ["import", "auto"] for b in blocks for ln in b)
    assert not any(" demo" in ln for b in blocks for ln in b), "the demo stays out of the quick blocks"
    for b in blocks:
        for ln in b:
            assert ln.startswith(".venv/bin/"), f"a README command should name the venv's program: {ln}"


def _run(line: str, cwd: Path, env: dict[str, str], weights: Path | None) -> subprocess.CompletedProcess[str]:
    argv = shlex.split(line)
    exe = {".venv/bin/capnav": [sys.executable, "-m", "capnav.cli"], ".venv/bin/python": [sys.executable]}
    argv = exe[argv[0]] + argv[1:]
    if argv[3:5] == ["models", "install"] and "--from" not in argv:
        if weights is None:
            pytest.skip("installing detector weights needs ../shared/weights here (tests never download)")
        argv += ["--from", str(weights)]
    return subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True, timeout=1800)


@pytest.mark.parametrize("k", range(len(quick_blocks())))
def test_quick_block_runs_line_by_line(k: int, tmp_path: Path) -> None:
    env = {**os.environ, "PYTHONPATH": str(REPO / "src"), "CAPNAV_MODELS": str(tmp_path / "models")}
    shared = Path(os.environ.get("CAPNAV_SHARED", REPO.parent / "shared"))
    weights = shared / "weights" if (shared / "weights").is_dir() else None
    for line in quick_blocks()[k]:
        r = _run(line, tmp_path, env, weights)
        assert r.returncode == 0, f"{line}\nexit {r.returncode}\n{r.stdout[-2000:]}\n{r.stderr[-2000:]}"
        assert "Traceback" not in r.stderr, line
        assert "camera jumped" not in r.stderr, f"{line}: a pose-jump warning on the simulator's own data"
