"""Does a detector label answer a goal text? The exploration baselines' stand-in for CLIP.

CoW scores image regions against the goal with CLIP; these baselines have no CLIP, only the
shared detector's labels and the offline text embedder. A goal that names a vocabulary category
(or a synonym) is answered exactly by that label; otherwise (a free-form phrase) a label answers
it when its text embedding is similar enough. The similarity of every label to the goal is
also kept as a graded score, used to rank frontiers (ZSON) and graph nodes (LM-Nav).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError
from capnav.eval.methods.words import category_in_text
from capnav.language.embedder import TextEmbedder


@dataclass
class GoalMatcher:
    """Scores detector labels against one goal text; ``accepts`` says which labels *are* the goal."""

    goal_text: str
    embedder: TextEmbedder
    threshold: float = 0.6  # cosine above which a label answers a free-form goal
    category: str | None = field(init=False)
    _goal_vec: NDArray[np.float32] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if not self.goal_text.strip():
            raise InputError("goal text is empty")
        self.category = category_in_text(self.goal_text)
        self._goal_vec = self.embedder.embed_one(self.goal_text)

    def similarity(self, labels: list[str]) -> NDArray[np.float64]:
        """Cosine similarity of each label to the goal text; the goal's own category scores 1."""
        if not labels:
            return np.zeros(0)
        sims = (self.embedder.embed(labels) @ self._goal_vec).astype(np.float64)
        if self.category is not None:
            sims[[lab == self.category for lab in labels]] = 1.0
        return sims

    def accepts(self, labels: list[str]) -> NDArray[np.bool_]:
        """Which labels are the goal: the exact category when the goal names one, else similarity."""
        if not labels:
            return np.zeros(0, bool)
        if self.category is not None:
            return np.array([lab == self.category for lab in labels], bool)
        return self.similarity(labels) >= self.threshold
