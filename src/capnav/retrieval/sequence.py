"""Several goals in one request ("the fridge, then the blue sofa"): each goal is retrieved in
turn, from where the robot will stand after the previous one (its chosen object), and the first
goal that is not found stops the sequence with its reason: going on to the second goal when the
first does not exist would not be what was asked."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from capnav.retrieval.result import QueryResult
    from capnav.retrieval.retriever import Retriever


@dataclass
class GoalSequence:
    """The answers of every goal retrieved, in order; ``stopped`` says why the sequence ended
    early ("" when every goal was found)."""

    instruction: str
    goals: list[str]  # each goal's words, in order (all of them, also those not reached)
    results: list[QueryResult] = field(default_factory=list)
    stopped: str = ""

    @property
    def found(self) -> bool:
        return len(self.results) == len(self.goals) and all(r.found for r in self.results)

    def to_dict(self) -> dict[str, Any]:
        """The first goal's answer at the top level (the single-goal shape), and for several goals
        every answer in ``goals`` with ``stopped``."""
        out = self.results[0].to_dict()
        if len(self.goals) > 1:
            out["goals"] = [{"goal": k + 1, "text": self.goals[k], **r.to_dict()} for k, r in enumerate(self.results)]
            out["goals_total"] = len(self.goals)
            out["stopped"] = self.stopped
        return out


def query_goals(retriever: Retriever, instruction: str, robot_xy: tuple[float, float] | None = None) -> GoalSequence:
    """Retrieve every goal of ``instruction`` in order; a goal not found stops the sequence."""
    queries = retriever.read_goals(instruction)
    seq = GoalSequence(instruction, [q.text for q in queries])
    xy = robot_xy
    for k, q in enumerate(queries):
        res = retriever.query(q, robot_xy=xy)
        seq.results.append(res)
        if not res.found:
            if k + 1 < len(queries):
                seq.stopped = (f"goal {k + 1} of {len(queries)} ({q.text!r}) was not found, so the "
                               f"{len(queries) - k - 1} goal(s) after it were not tried")
            break
        assert res.chosen is not None
        xy = (float(res.chosen.position[0]), float(res.chosen.position[1]))
    return seq
