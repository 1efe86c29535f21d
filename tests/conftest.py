"""Test-wide fixtures: where the shared, read-only material (real frames, detector weights,
hand-written phrasings) lives. It sits beside the repository as ``../shared`` (CI always has it)
or wherever ``CAPNAV_SHARED`` points; it is never copied into the repository."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def _shared_dir() -> Path | None:
    env = os.environ.get("CAPNAV_SHARED")
    cands = [Path(env)] if env else []
    cands.append(REPO.parent / "shared")
    for c in cands:
        if c.is_dir():
            return c
    return None


@pytest.fixture(scope="session")
def shared_dir() -> Path:
    """The shared folder; skipped when absent, unless CAPNAV_REQUIRE_SHARED=1 (CI), then failed."""
    d = _shared_dir()
    if d is None:
        msg = "../shared (real frames, weights, phrasings) not found; set CAPNAV_SHARED"
        if os.environ.get("CAPNAV_REQUIRE_SHARED") == "1":
            pytest.fail(msg)
        pytest.skip(msg)
    return d
