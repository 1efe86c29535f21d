"""Which moves of a camera stream are jumps: a move much longer than the stream's own usual step.

A fixed limit in metres cannot tell a dropped stretch of frames from a stream that was recorded or
kept sparsely: the simulator's exploration walks 0.5 m between frames, so every 3rd frame of it
moves 1.5 m, and a 30-frame summary of an apartment moves metres each time, all as intended. So a
move is a jump when it is longer than ``floor`` *and* ``factor`` times the stream's usual step (the
75th percentile of its steps; with few steps, that of the other steps; with fewer than
``MIN_STEPS``, ``floor`` alone). On the simulator's own exploration of apartments 0-9 (default
size) and 0-2 (large), whole or thinned to every 2nd-8th frame or to 6-200 frames, the longest move
is at most 2.8 times that usual step (tests/mapping/test_motion.py checks a sample), so ``factor``
4 reports none of them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

#: A move shorter than this (m) is a rotation in place, not a step.
STILL_M = 1e-3
#: A stream with fewer steps has no usual step: its moves are judged against ``floor`` alone.
MIN_STEPS = 5
#: Below this many steps each move is judged against the others' usual step (one jump among few
#: steps would otherwise be its own reference).
FEW_STEPS = 8


@dataclass(frozen=True)
class PoseJumps:
    """The jumps of one stream and what they were judged against."""

    jumps: list[dict[str, Any]]  # {"frame": index of the frame after the jump, "metres": move}
    usual_step: float | None  # m, the 75th percentile of the stream's steps (None: fewer than 2)
    limit: float  # m, the shortest move that would have been a jump (for the whole stream)

    def message(self) -> str:
        """One line for the log: how many, where, against what, and what to check."""
        if not self.jumps:
            return ""
        n = len(self.jumps)
        frames = ", ".join(str(j["frame"]) for j in self.jumps[:5]) + (", ..." if n > 5 else "")
        longest = max(j["metres"] for j in self.jumps)
        usual = f" (its usual step is {self.usual_step:.2f} m)" if self.usual_step else ""
        return (f"the camera jumped more than {self.limit:.2f} m between consecutive frames {n} "
                f"time{'s' if n > 1 else ''}{usual}, longest {longest:.2f} m, before frame{'s' if n > 1 else ''} "
                f"{frames}: if frames were dropped there, parts of the map may be missing or doubled; if the "
                "poses come from your own recording, check that they are camera-to-world in metres "
                "(docs/conventions.md); listed in the map's meta['pose_jumps']")


def find_pose_jumps(frames: ArrayLike, eyes: ArrayLike, floor: float = 1.5, factor: float = 4.0) -> PoseJumps:
    """Judge the moves between consecutive camera centres ``eyes`` (N, 3) of ``frames`` (N indices)."""
    idx = np.asarray(frames)
    e = np.asarray(eyes, dtype=np.float64).reshape(-1, 3)
    if len(e) < 2:
        return PoseJumps([], None, floor)
    moves = np.linalg.norm(np.diff(e, axis=0), axis=1)
    steps = moves > STILL_M
    n = int(steps.sum())
    usual = float(np.percentile(moves[steps], 75)) if n >= MIN_STEPS else None
    limits = np.full(len(moves), floor if usual is None else max(floor, factor * usual))
    if usual is not None and n < FEW_STEPS:  # each step against the others, not against itself too
        for i in np.flatnonzero(steps):
            others = moves[steps & (np.arange(len(moves)) != i)]
            limits[i] = max(floor, factor * float(np.percentile(others, 75)))
    jumps = [{"frame": int(idx[i + 1]), "metres": round(float(moves[i]), 3)} for i in np.flatnonzero(moves > limits)]
    return PoseJumps(jumps, usual, floor if usual is None else max(floor, factor * usual))
