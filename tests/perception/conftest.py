"""Perception tests reuse the mapping tests' numpy ray-caster and hash embedder."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "mapping"))
