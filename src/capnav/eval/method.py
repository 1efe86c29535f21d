"""The contract between the evaluation harness and a navigation method (CapNav, ablations, baselines).

A method sees one apartment through a :class:`SceneContext` (the simulator only to drive and
observe its agent, the shared prior map, detector, embedder and exploration stream) and is asked
for one subgoal at a time. It never sees the scene manifest or the episode's ground truth: the
harness alone scores where the agent stopped.

Life cycle, per apartment: the harness builds one ``SceneContext``; per episode it spawns an agent
at the episode's start pose and calls ``start_episode(ctx, agent)``; then ``run_subgoal`` for the 4
goals in order, each starting where the previous one stopped. ``ctx`` is the same object for all
episodes of an apartment, so per-apartment work (a retriever, a topological graph) can be cached
in ``ctx.cache``.
"""

from __future__ import annotations

import importlib
import pkgutil
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

from capnav.core.registry import Registry

if TYPE_CHECKING:
    from capnav.core.grid import OccupancyGrid
    from capnav.language.embedder import TextEmbedder
    from capnav.mapping.cmap import CapNavMap
    from capnav.perception.base import Detector

# The simulator and dataset types are passed through untouched; typed loosely and documented.
Simulator = Any  # capnav.sim simulator: spawn_agent(x, y, yaw) -> Agent, observe
Agent = Any  # capnav.sim agent: pose (x, y, yaw), step(action), move_to(x, y), trajectory, path_length
DatasetReader = Any  # capnav.io.dataset reader of the shared exploration stream


@dataclass
class SceneContext:
    """Everything a method may use in one apartment.

    ``sim`` is ONLY for spawning, driving and observing the agent: methods must not read
    ``sim.manifest`` (that is ground truth). ``prior_map`` is built once from the shared
    exploration stream with the shared detector, identical for every map-based method;
    ``occupancy`` is its navigable top-down grid (FREE/OCCUPIED/UNKNOWN).
    """

    scene_seed: int
    seed: int  # seed for the method's own random choices in this apartment
    sim: Simulator
    embedder: TextEmbedder
    detector: Detector | None = None
    prior_map: CapNavMap | None = None
    occupancy: OccupancyGrid | None = None  # navigable top-down grid of the prior map
    frames: DatasetReader | None = None
    workdir: Path | None = None  # a per-apartment scratch folder the method may write caches to
    max_steps: int = 500  # motion budget per subgoal (agent steps)
    cache: dict[str, Any] = field(default_factory=dict)


@dataclass
class SubgoalOutcome:
    """What a method reports after one subgoal. The harness measures the stop pose, path length
    and success itself from the agent and the ground truth; these fields explain the decision.

    ``target_xy`` is where the method decided the goal is (an object centroid or a map region);
    ``chosen_object`` the prior-map object id when the method picked one; ``query_time_s`` the
    wall time of the decision (retrieval / scoring), excluding motion.
    """

    found: bool
    reason: str = ""
    target_xy: tuple[float, float] | None = None
    chosen_object: int | None = None
    query_time_s: float = 0.0
    steps: int = 0
    explanation: str = ""  # e.g. the chosen object's caption and score
    extra: dict[str, Any] = field(default_factory=dict)


@runtime_checkable
class NavMethod(Protocol):
    """A navigation method. ``uses_prior_map`` tells the harness whether to build the shared map."""

    name: str
    uses_prior_map: bool

    def start_episode(self, ctx: SceneContext, agent: Agent) -> None:
        """Called once per episode, after the agent is spawned at the start pose."""
        ...

    def run_subgoal(self, goal_text: str, agent: Agent) -> SubgoalOutcome:
        """Drive ``agent`` towards ``goal_text`` and stop; return why it stopped there."""
        ...


METHODS: Registry[NavMethod] = Registry("method")

#: Packages whose modules register methods; all their modules are imported by ``load_methods``.
_METHOD_PACKAGES = ("capnav.eval.methods", "capnav.eval.baselines")


def load_methods() -> list[str]:
    """Import every method module (so their ``@METHODS.register`` run) and return the names."""
    for pkg_name in _METHOD_PACKAGES:
        try:
            pkg = importlib.import_module(pkg_name)
        except ModuleNotFoundError as e:
            if e.name != pkg_name:
                raise
            continue
        _import_tree(pkg)
    return METHODS.names()


def _import_tree(pkg: Any) -> None:
    for mod in pkgutil.walk_packages(pkg.__path__, prefix=pkg.__name__ + "."):
        if mod.name.rsplit(".", 1)[-1].startswith("_"):
            continue
        importlib.import_module(mod.name)


def create_method(name: str, **cfg: Any) -> NavMethod:
    """Build a registered method by name (``InputError`` listing the names if unknown)."""
    load_methods()
    return METHODS.create(name, **cfg)


def method_note(name: str) -> str:
    """The docstring of the module that implements method ``name`` (what it is, how it differs)."""
    import sys

    load_methods()
    m = METHODS.create(name)
    doc = sys.modules[type(m).__module__].__doc__ or ""
    return doc.strip()
