"""The main job on one generated apartment: explore, map, caption, embed, ask, navigate, report.

The pipeline (mapping, captioning, retrieval, planning) sees observations only; the simulator's
truth is used here for two things a user would want from a demo: choosing instructions that
single out one object among lookalikes, and saying afterwards whether the agent reached the
object the instruction meant.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from rich.console import Console
from rich.markup import escape

from capnav.core.atomic import write_bytes, write_json
from capnav.core.console import make_console
from capnav.core.errors import CapNavError, InputError
from capnav.core.footprint import footprint_distance
from capnav.core.grid import FREE
from capnav.core.limits import check_count, check_image_size
from capnav.core.text import shorten
from capnav.demo.report import Report, ReportItem, verdict, write_html, write_markdown
from capnav.mapping.objects import MapObject
from capnav.pipeline import PipelineConfig, SimScene, open_sim_scene
from capnav.pipeline.drive import run_instruction
from capnav.planning import PlannerConfig
from capnav.retrieval import RetrievalConfig, Retriever, create_verifier
from capnav.sim.geodesic import walker
from capnav.sim.instructions import Walk, generate_instructions
from capnav.sim.navgrid import start_cells
from capnav.sim.success import SUCCESS_RADIUS_M, distance_to_instances, room_index

#: One instruction of each kind by default: what CapNav is for first, then the classic cases.
DEFAULT_KINDS = ("attribute", "superlative", "relation", "closest", "room", "category", "absent")


@dataclass
class DemoConfig:
    seed: int = 0
    out: Path = Path("runs/demo")
    width: int = 320
    height: int = 240
    max_frames: int | None = None
    kinds: tuple[str, ...] = DEFAULT_KINDS
    instructions: tuple[str, ...] = ()  # the user's own; replaces the generated ones when given
    verifier: str = "offline"
    captioner: str = "offline"

    def __post_init__(self) -> None:
        if self.seed < 0:
            raise InputError(f"seed must be >= 0, got {self.seed}")
        check_image_size(self.width, self.height)
        check_count("max_frames", self.max_frames, optional=True)


@dataclass
class DemoResult:
    report_html: Path
    report_md: Path
    items: list[ReportItem]
    timings: dict[str, float] = field(default_factory=dict)


def _png(obj: MapObject) -> bytes | None:
    for v in obj.views:
        if v.frame_png:
            return v.frame_png
    return None


def _off_facing_deg(pose: tuple[float, float, float], footprint: NDArray[np.float64]) -> float:
    """How far (degrees) the heading at ``pose`` turns away from the object: 0 when it points at some
    part of the footprint (within the angle its corners span from the stop point, or standing on it)."""
    x, y, yaw = pose
    p = np.array([[x, y]], dtype=np.float64)
    if footprint_distance(p, footprint)[0] == 0.0:
        return 0.0
    def wrap(a: Any) -> Any:
        return (a + np.pi) % (2 * np.pi) - np.pi

    centre = np.arctan2(footprint[:, 1].mean() - y, footprint[:, 0].mean() - x)
    span = wrap(np.arctan2(footprint[:, 1] - y, footprint[:, 0] - x) - centre)  # corners, around the centre
    lo, hi, h = float(span.min()), float(span.max()), float(wrap(yaw - centre))
    return 0.0 if lo <= h <= hi else float(np.degrees(min(abs(wrap(h - lo)), abs(wrap(h - hi)))))


def _next_instruction(cfg: DemoConfig, k: int, sim: Any, robot_xy: tuple[float, float], walk: Walk
                      ) -> tuple[str, str, list[int]] | None:
    """The k-th instruction (text, kind, target ids): the user's, or one generated for the k-th kind
    from where the robot stands now (so that "closest" means closest to the robot when it is asked)."""
    if cfg.instructions:
        return (cfg.instructions[k], "user", [])
    made = generate_instructions(sim.manifest, per_kind=1, seed=cfg.seed * 1000 + k, kinds=(cfg.kinds[k],),
                                 robot_xy=robot_xy, walk=walk)
    return (made[0].text, made[0].kind, list(made[0].targets)) if made else None


def run_demo(cfg: DemoConfig, console: Console | None = None) -> DemoResult:
    con = console or make_console(stderr=True)
    out = cfg.out
    (out / "images").mkdir(parents=True, exist_ok=True)
    timings: dict[str, float] = {}

    t0 = time.perf_counter()
    pcfg = PipelineConfig(width=cfg.width, height=cfg.height, max_frames=cfg.max_frames,
                          captioner=cfg.captioner, verifier=cfg.verifier)
    con.print(f"[bold]1/4[/] apartment seed {cfg.seed}: building the simulator")
    assets = open_sim_scene(cfg.seed, cfg.seed, pcfg, out)  # the product pipeline: it never reads the truth
    sim = assets.sim
    nav_truth = sim.navigable()  # the simulator's truth: only to pick starts and instructions and to judge
    starts = start_cells(sim.nav_grid().clearance, nav_truth.cells == FREE,
                         PlannerConfig().inflation + nav_truth.spec.resolution)
    footprints = {o.id: np.asarray(o.footprint, dtype=np.float64) for o in sim.manifest.objects}
    rooms = [np.asarray(r.polygon, dtype=np.float64) for r in sim.manifest.rooms]
    walk = walker(nav_truth.spec, nav_truth.cells == FREE)  # "closest" along the true floor
    con.print(f"     {len(sim.manifest.rooms)} rooms, {len(sim.manifest.objects)} objects "
              f"({time.perf_counter() - t0:.1f} s)")
    from capnav.viz.scene import draw_scene

    draw_scene(sim.manifest, out / "images" / "apartment.png", navigable=nav_truth, id_prefix="T",
               title=f"apartment seed {cfg.seed} as simulated (truth; T-numbers are truth ids, not map ids)")

    t1 = time.perf_counter()
    con.print("[bold]2/4[/] exploring, mapping (SG3DTracker + voxel map), captioning and embedding")
    cmap = assets.prior_map()
    timings.update(assets.timings)
    con.print(f"     {len(assets.stream())} frames -> {len(cmap.objects)} objects in the map "
              f"({time.perf_counter() - t1:.1f} s); map saved to {out / 'map.capnav'}")

    retriever = Retriever(cmap, assets.embedder, create_verifier(cfg.verifier), RetrievalConfig())
    rng = np.random.default_rng(cfg.seed + 1)
    cells = np.argwhere(starts if starts.any() else nav_truth.cells == FREE)
    if len(cells) == 0:
        raise CapNavError(f"apartment seed {cfg.seed} has no free cell to start from")
    sx, sy = nav_truth.spec.to_world(cells[int(rng.integers(len(cells)))])
    start_yaw = float(rng.uniform(-np.pi, np.pi))
    agent = sim.spawn_agent(float(sx), float(sy), start_yaw)
    n = len(cfg.instructions) or len(cfg.kinds)

    con.print(f"[bold]3/4[/] answering {n} instructions and navigating")
    items: list[ReportItem] = []
    pcfg_plan = PlannerConfig()
    for k in range(n):
        x, y, _ = agent.pose
        nxt = _next_instruction(cfg, k, sim, (float(x), float(y)), walk)
        if nxt is None:
            con.print(f"     (this apartment allows no {cfg.kinds[k]!r} instruction; skipped)")
            continue
        text, kind, targets = nxt
        it = _answer(len(items) + 1, text, kind, targets, retriever, agent, cmap, assets, footprints, rooms,
                     pcfg_plan, out)
        items.append(it)
        con.print(f"     {len(items)}. \\[{kind}] {escape(repr(shorten(text)))}: {it.chosen_label or '-'}: "
                  f"{escape(verdict(it))}")

    con.print("[bold]4/4[/] writing the report")
    timings["total"] = time.perf_counter() - t0
    judged = [it for it in items if it.correct is not None]
    driven = [it for it in items if it.in_room is not None]
    summary = [
        ("apartment seed", str(cfg.seed)),
        ("rooms / objects (truth)", f"{len(sim.manifest.rooms)} / {len(sim.manifest.objects)}"),
        ("frames explored", str(len(assets.stream()))),
        ("objects in the map", str(len(cmap.objects))),
        ("instructions right (truth)", f"{sum(bool(it.correct) for it in judged)} / {len(judged)}"),
        ("stops in the object's room, facing it (truth)",
         f"{sum(bool(it.in_room) and it.facing_deg == 0.0 for it in driven)} / {len(driven)}"),
        ("time (s)", ", ".join(f"{k} {v:.1f}" for k, v in timings.items())),
    ]
    from capnav.viz.mapimage import map_picture

    write_bytes(out / "images" / "map.png", map_picture(cmap).png)
    report = Report(f"CapNav demo: apartment {cfg.seed}", summary, items, overview_png="images/map.png",
                    truth_png="images/apartment.png")
    md, html_path = out / "report.md", out / "report.html"
    write_markdown(report, md)
    write_html(report, html_path)
    write_json(out / "report.json", {"summary": dict(summary), "items": [vars(it) for it in items]})
    con.print(f"     {html_path}")
    return DemoResult(html_path, md, items, timings)


def _answer(k: int, text: str, kind: str, targets: list[int], retriever: Retriever, agent: Any, cmap: Any,
            assets: SimScene, footprints: dict[int, NDArray[np.float64]], rooms: list[NDArray[np.float64]],
            plan_cfg: PlannerConfig, out: Path) -> ReportItem:
    try:
        res = run_instruction(cmap, assets.sim, retriever, text, agent=agent, config=plan_cfg,
                              out_dir=out / "images", stem=f"{k:02d}_nav")
    except CapNavError as e:  # e.g. an empty or non-English instruction: report it, keep going
        return ReportItem(text, kind, False, None, None, None, None, str(e), rejected=True,
                          correct=None if kind == "user" else False)
    q, nav, obj = res.query, res.nav, res.query.chosen
    item = ReportItem(text, kind, q.found, obj.id if obj else None, obj.label if obj else None,
                      obj.caption if obj else None, q.score if q.found else None, q.reason,
                      runners_up=[f"{o.id} {o.label}" for o, _ in q.ranked[:3]], timings=dict(q.timings),
                      candidates=_candidates(q))
    if kind == "absent":
        item.correct = not q.found
    elif targets:  # right only when the agent stops within reach of an instance the instruction meant
        fps = [footprints[t] for t in targets]
        if obj is not None:  # the chosen object is right when the nearest true instance to it is meant
            near = min(footprints, key=lambda i: distance_to_instances(obj.position[:2], [footprints[i]]))
            item.right_object = near in targets
        if nav is not None:
            item.truth_distance = distance_to_instances(nav.final_pose[:2], fps)
            meant = fps[int(np.argmin([distance_to_instances(nav.final_pose[:2], [f]) for f in fps]))]
            item.in_room = room_index(nav.final_pose[:2], rooms) == room_index(meant.mean(axis=0), rooms) >= 0
            item.facing_deg = _off_facing_deg(nav.final_pose, meant)
        item.correct = item.truth_distance is not None and item.truth_distance <= SUCCESS_RADIUS_M
    if obj is not None and (view := _png(obj)):
        item.view_png = f"images/{k:02d}_view.png"
        write_bytes(out / item.view_png, view)
    if nav is not None:
        item.reached, item.nav_reason, item.path_length = nav.reached, nav.reason, nav.path_length
    if res.png is not None:
        item.map_png = f"images/{res.png.name}"
    return item


def _candidates(q: Any, n: int = 4) -> list[dict[str, Any]]:
    """The chosen object and up to ``n`` runners-up with each score on its own scale."""
    out: list[dict[str, Any]] = []
    if q.chosen is not None:
        ver = q.verification
        out.append({"id": q.chosen.id, "label": q.chosen.label, "similarity": q.score, "verifier": ver,
                    "final": ver if ver is not None else q.score, "why": "chosen", "chosen": True})
    for k, (o, final) in enumerate(q.ranked[:n]):
        d = q.details[k] if k < len(q.details) else {}
        out.append({"id": o.id, "label": o.label, "similarity": d.get("similarity"), "verifier": d.get("verifier"),
                    "final": final, "why": d.get("why", ""), "chosen": False})
    return out
