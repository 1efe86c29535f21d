"""``python -m capnav`` runs the command line, as the helpers' and users' first try did (it said
"'capnav' is a package and cannot be directly executed")."""

from __future__ import annotations

import subprocess
import sys


def test_python_dash_m_capnav_runs_the_cli() -> None:
    out = subprocess.run([sys.executable, "-m", "capnav", "--help"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "sim" in out.stdout and "navigate" in out.stdout
