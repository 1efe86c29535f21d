"""One instruction end to end in the simulator: retrieve the described object, plan to it, drive
the simulated agent there, draw it (``capnav navigate`` and the demo). It is the product's motion
side, not the benchmark's: it never imports the evaluation (an episode file is read as the JSON
it is, for its start pose only).

The pipeline sees the map only; the simulator is the world the agent drives in (its obstacles
are read only when the caller asks to plan on the true occupancy, for comparison).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from capnav.core.errors import DatasetError, InputError
from capnav.core.grid import OccupancyGrid
from capnav.planning.config import PlannerConfig
from capnav.planning.execute import NavResult, navigate_to
from capnav.planning.sight import map_columns, object_heights

if TYPE_CHECKING:
    from capnav.mapping.cmap import CapNavMap
    from capnav.retrieval.query import ParsedQuery
    from capnav.retrieval.result import QueryResult
    from capnav.retrieval.retriever import Retriever
    from capnav.sim.simulator import Simulator

OCCUPANCY_KINDS = ("mapped", "truth")


@dataclass
class InstructionOutcome:
    instruction: str
    query: QueryResult
    nav: NavResult | None
    start: tuple[float, float, float]
    occupancy: str
    png: Path | None = None
    json: Path | None = None

    @property
    def reached(self) -> bool:
        return self.nav is not None and self.nav.reached

    def to_dict(self) -> dict[str, Any]:
        return {"instruction": self.instruction, "occupancy": self.occupancy,
                "start": [round(v, 4) for v in self.start], "retrieval": self.query.to_dict(),
                "navigation": None if self.nav is None else self.nav.to_dict()}


def parse_pose(text: str) -> tuple[float, float, float]:
    """``"X,Y"`` or ``"X,Y,YAW"`` (metres, radians) -> (x, y, yaw)."""
    try:
        vals = [float(v) for v in text.replace(" ", "").split(",")]
    except ValueError:
        raise InputError(f"start must be X,Y or X,Y,YAW numbers, got {text!r}") from None
    if len(vals) not in (2, 3) or not np.isfinite(vals).all():
        raise InputError(f"start must be X,Y or X,Y,YAW finite numbers, got {text!r}")
    return vals[0], vals[1], vals[2] if len(vals) == 3 else 0.0


def episode_start(path: str | Path, episode_id: str | None = None) -> tuple[int, tuple[float, float, float]]:
    """Scene seed and start pose of an episode of an episode file (the first when no id is given)."""
    from capnav.core.jsonfile import read_json_object

    data = read_json_object(Path(path), "episode file")
    if data.get("format") != "capnav-episodes":
        raise DatasetError(f"{path} is not a CapNav episode file (format {data.get('format')!r})")
    eps = data.get("episodes")
    if not isinstance(eps, list) or not eps:
        raise InputError(f"{path} holds no episodes")
    match = [e for e in eps if isinstance(e, dict) and (episode_id is None or e.get("id") == episode_id)]
    if not match:
        ids = ", ".join(str(e.get("id")) for e in eps[:8] if isinstance(e, dict))
        raise InputError(f"no episode {episode_id!r} in {path} (first ids: {ids})")
    e = match[0]
    s = e.get("start")
    if not isinstance(s, dict):
        raise InputError(f"episode {e.get('id')} of {path} has no start pose; give --start X,Y,YAW")
    try:
        pose = (float(s["x"]), float(s["y"]), float(s.get("yaw", 0.0)))
        seed = int(e["scene_seed"])
    except (KeyError, TypeError, ValueError) as err:
        raise DatasetError(f"episode {e.get('id')} of {path}: bad start or scene_seed ({err})") from None
    return seed, pose


def random_start(sim: Simulator, seed: int) -> tuple[float, float, float]:
    """A seeded navigable start pose (when no episode or ``--start`` gives one)."""
    rng = np.random.default_rng([seed, 5])
    x, y = sim.random_navigable_point(rng)
    return x, y, float(rng.uniform(-np.pi, np.pi))


def planning_occupancy(cmap: CapNavMap, sim: Simulator, kind: str) -> OccupancyGrid:
    if kind == "mapped":
        return cmap.occupancy
    if kind == "truth":
        return sim.obstacles(resolution=cmap.occupancy.spec.resolution)
    raise InputError(f"occupancy must be one of {', '.join(OCCUPANCY_KINDS)}, got {kind!r}")


def run_instruction(cmap: CapNavMap, sim: Simulator, retriever: Retriever, instruction: str | ParsedQuery,
                    start: tuple[float, float, float] | None = None, occupancy: str = "mapped",
                    config: PlannerConfig | None = None, out_dir: str | Path | None = None,
                    stem: str = "navigate", agent: Any | None = None) -> InstructionOutcome:
    """Retrieve, plan, execute; with ``out_dir`` write ``<stem>.png`` and ``<stem>.json``.

    Give either ``start`` (a new agent is spawned there) or a live ``agent`` (it goes on from where
    it stands, as in a chain of instructions). ``instruction`` may be one goal already parsed.
    """
    cfg = config or PlannerConfig()
    occ = planning_occupancy(cmap, sim, occupancy)
    if agent is None:
        if start is None:
            raise InputError("run_instruction needs a start pose or an agent")
        agent = sim.spawn_agent(*start)
    else:
        x, y, yaw = agent.pose
        start = (float(x), float(y), float(yaw))
    query = retriever.query(instruction, robot_xy=(start[0], start[1]))
    nav = None
    if query.found and query.chosen is not None:
        nav = navigate_to(agent, occ, query.chosen.footprint, cfg, z_range=object_heights(query.chosen),
                          columns=map_columns(cmap))
    text = instruction if isinstance(instruction, str) else instruction.text
    out = InstructionOutcome(text, query, nav, start, occupancy)
    if out_dir is not None:
        from capnav.viz.topdown import short_label, write_navigation

        chosen = query.chosen
        if nav is None:
            title = f'"{text}": no object chosen ({query.reason})'
        else:
            title = (f'"{text}" -> {short_label(chosen) if chosen else "?"}: '
                     f"{'reached' if nav.reached else 'NOT reached'}, {nav.distance_to_object:.2f} m from it, "
                     f"path {nav.path_length:.1f} m, {nav.replans} replans")
        out.png, out.json = write_navigation(
            out_dir, stem, occ, cmap.objects, chosen.id if chosen else None,
            None if nav is None else nav.waypoints, None if nav is None else nav.trajectory, start,
            agent.pose, title, goal=None if nav is None or nav.goal is None else (*nav.goal.xy, nav.goal.yaw),
            reach=cfg.reach, abandoned=[] if nav is None else [p.waypoints for p in nav.plans[:-1]],
            **{k: v for k, v in out.to_dict().items() if k != "start"})
    return out
