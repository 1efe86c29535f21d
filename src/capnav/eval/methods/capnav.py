"""CapNav and its two ablations (the paper's Table 2) as benchmark methods.

All three query the same caption-enriched map with the same retriever (paper 3.4) and differ only
in ``RetrievalConfig``: ``capnav`` verifies the top candidates (the AGENT step, here the configured
verifier, offline by default) and uses the attribute heuristic; ``capnav-no-verify`` takes the top
semantic match; ``capnav-no-heuristic`` ranks every instruction by caption similarity, never
turning a bare category into a "closest" query.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

from capnav.core.errors import InputError
from capnav.eval.method import METHODS, Agent, NavMethod, SceneContext
from capnav.eval.methods.base import Decision, PriorMapMethod, object_decision
from capnav.planning import PlannerConfig
from capnav.retrieval.config import RetrievalConfig
from capnav.retrieval.query import parse_goals
from capnav.retrieval.retriever import Retriever
from capnav.retrieval.verifier import create_verifier


class CapNavMethod(PriorMapMethod):
    """Retrieve the described instance from the caption map, then plan to it with A*."""

    def __init__(self, name: str, retrieval: RetrievalConfig, verifier: str = "offline",
                 planner: PlannerConfig | None = None) -> None:
        super().__init__(planner)
        self.name = name
        self.retrieval = retrieval
        self.verifier_name = verifier
        self.retriever: Retriever | None = None
        self._heard: tuple[str, int, bool] = ("", 0, True)  # last text, its goal index, found so far

    def start_episode(self, ctx: SceneContext, agent: Agent) -> None:
        self._heard = ("", 0, True)
        super().start_episode(ctx, agent)

    def prepare(self, ctx: SceneContext) -> None:
        verifier = create_verifier(self.verifier_name, embedder=ctx.embedder) if self.retrieval.use_verifier else None
        self.retriever = Retriever(self.cmap, ctx.embedder, verifier, self.retrieval)

    def decide(self, goal_text: str, robot_xy: tuple[float, float]) -> Decision | str:
        if self.retriever is None:
            raise InputError(f"{self.name}: decide() before prepare()")
        # A request of several goals ("the sink, then the bed") is heard once per goal: the same
        # text again means its next goal, asked from where the robot now stands.
        last, k, ok = self._heard
        k = k + 1 if goal_text == last else 0
        if k and not ok:
            return "the goal before this one was not found, so the request stopped there"
        goals = parse_goals(goal_text, self.retriever.embedder)
        if k >= len(goals):
            self._heard = (goal_text, k, False)
            return f"the instruction names {len(goals)} goal(s), not {k + 1}"
        res = self.retriever.query(goals[k] if len(goals) > 1 else goal_text, robot_xy)
        self._heard = (goal_text, k, res.found)
        if not res.found or res.chosen is None:
            return f"retrieval found nothing: {res.reason}"
        return object_decision(res.chosen, f"{res.mode}: {res.reason}",
                               f"{res.chosen.caption or res.chosen.label} (cos {res.score:.3f})")


def _factory(name: str, **switches: bool) -> Callable[..., NavMethod]:
    def make(planner: PlannerConfig | None = None, retrieval: RetrievalConfig | None = None,
             verifier: str = "offline", **_: object) -> NavMethod:
        cfg = replace(retrieval or RetrievalConfig(), **switches)  # type: ignore[arg-type]
        return CapNavMethod(name, cfg, verifier, planner)

    return make


METHODS.register("capnav")(_factory("capnav"))
METHODS.register("capnav-no-verify")(_factory("capnav-no-verify", use_verifier=False))
METHODS.register("capnav-no-heuristic")(_factory("capnav-no-heuristic", use_attribute_heuristic=False))
