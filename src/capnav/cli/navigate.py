"""``capnav navigate MAP "instruction"``: retrieve, choose a goal pose, plan with A*; drive in the
simulator when the map comes from ``capnav sim``, else write the goal and path for a robot stack.
With ``--search`` (simulator maps) the robot confirms the goal with its own camera and searches
for it when the map is silent or stale (``capnav.explore.search``).
A request of several goals ("the fridge, then the sofa") is planned or driven leg by leg, each
from where the one before ended; a leg that fails ends the sequence and the command fails."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

if TYPE_CHECKING:
    from rich.console import Console

    from capnav.mapping.cmap import CapNavMap
    from capnav.retrieval import ParsedQuery, Retriever


def register(app: typer.Typer) -> None:
    @app.command()
    def navigate(
        map_file: Annotated[Path, typer.Argument(help="map file with captions (capnav map + capnav caption)")],
        instruction: Annotated[str, typer.Argument(help='what to go to, e.g. "the white sofa with curved arms"')],
        scene: Annotated[int | None, typer.Option(
            "--scene", help="apartment seed to drive in (default: the seed recorded in the map)")] = None,
        start: Annotated[str | None, typer.Option(help="start pose X,Y[,YAW] (m, rad); default: the map's last "
                                                       "camera pose (seeded random for a map without one)")
                         ] = None,
        drive: Annotated[bool | None, typer.Option(
            "--drive/--plan-only", help="drive the simulated agent (default when the map comes from capnav sim) or "
                                        "only write the goal pose, path and map for a robot stack")] = None,
        seed: Annotated[int, typer.Option(help="seed of the random start")] = 0,
        episode: Annotated[Path | None, typer.Option(
            help="episode file (capnav eval): scene and start pose from its episode --episode-id")] = None,
        episode_id: Annotated[str | None, typer.Option(help="episode id in --episode (default: the first)")
                              ] = None,
        out: Annotated[Path, typer.Option("--out", "-o", help="folder for navigate.png / .json / _map.pgm+yaml")
                       ] = Path("runs/navigate"),
        occupancy: Annotated[str, typer.Option(help="plan on the 'mapped' occupancy or the simulator's 'truth'")
                             ] = "mapped",
        embedder: Annotated[str, typer.Option(help="text embedder backend (must match the map's captions)")
                            ] = "minilm",
        embedder_path: Annotated[Path | None, typer.Option(help="model folder for folder-based embedders")
                                 ] = None,
        verifier: Annotated[str, typer.Option(help="verification backend: offline, none, gemini, openai, ...")
                            ] = "offline",
        distance: Annotated[str, typer.Option(
            help="how 'closest' measures: walking (along the map's floor) or straight (eq. 17 grid distance)")
                            ] = "walking",
        through_unknown: Annotated[bool, typer.Option(
            "--through-unknown", help="accept a planned path that crosses unknown space (default: such a plan is "
                                      "reported as not ok)")] = False,
        search: Annotated[bool, typer.Option(
            "--search", help="simulator maps: confirm the goal with the robot's camera and, when the map has no such "
                             "object, it is not at its place or it is gone, search rooms and unseen space for it")
                          ] = False,
        budget_m: Annotated[float, typer.Option(help="--search: metres the robot may drive")] = 60.0,
        budget_s: Annotated[float | None, typer.Option(help="--search: seconds the search may take")] = None,
        visit: Annotated[int, typer.Option(help="drive in this visit of the simulated apartment (capnav sim --visit)")
                         ] = 1,
        changes: Annotated[str, typer.Option(help="the changes of --visit > 1, e.g. moved=3,removed=2,added=2")
                           ] = "",
        change_seed: Annotated[int, typer.Option(help="the seed of the changes of --visit > 1")] = 0,
    ) -> None:
        """Go to the object an instruction describes: a goal pose (x, y, yaw facing it) and an A* path in
        the map's frame (JSON, PNG, ROS map_server PGM + YAML), driven in the simulator for sim maps."""
        from capnav.cli.options import check_map_scene, check_model_folder, check_output_dir, check_verifier
        from capnav.core.console import make_console
        from capnav.core.errors import InputError
        from capnav.io.mapfile import load_map
        from capnav.language import create_embedder
        from capnav.language.embedder import EMBEDDERS
        from capnav.pipeline.drive import OCCUPANCY_KINDS, episode_start, parse_pose
        from capnav.retrieval import RetrievalConfig, Retriever, create_verifier

        if occupancy not in OCCUPANCY_KINDS:  # fail before the slow loading below
            raise InputError(f"occupancy must be one of {', '.join(OCCUPANCY_KINDS)}, got {occupancy!r}")
        check_output_dir(out, "--out")
        check_verifier(verifier)
        check_model_folder("--embedder", embedder, embedder_path, "--embedder-path", EMBEDDERS.required(embedder))
        given = parse_pose(start) if start else None
        ep_scene = None
        if episode is not None:
            ep_scene, ep_pose = episode_start(episode, episode_id)
            given = given or ep_pose
        cmap = load_map(map_file)
        # The map, --scene and the episode must be the same apartment (the map records where it was made).
        check_map_scene(cmap.meta, map_file, scene, f"--scene {scene}")
        check_map_scene(cmap.meta, map_file, ep_scene, f"the episode in {episode}")
        if scene is not None and ep_scene is not None and scene != ep_scene:
            raise InputError(f"--scene {scene} is not the episode's apartment {ep_scene} ({episode})")
        scene_seed = next((s for s in (scene, ep_scene, cmap.meta.get("scene_seed")) if s is not None), None)
        if search and (scene_seed is None or drive is False):
            raise InputError(f"--search drives the simulated robot and looks with its camera, but {map_file} "
                             + ("is a map of a recording with no simulator scene (no scene seed)" if scene_seed is None
                                else "is to be planned only (--plan-only)")
                             + ": drop --search to plan on the map alone, or give --scene SEED for a simulated "
                               "apartment")
        from capnav.sim.changes import ChangeSpec

        spec = ChangeSpec.parse(changes) if changes else None
        if visit < 1 or (visit == 1 and spec is not None):
            raise InputError(f"--visit {visit} with --changes {changes!r}: changes apply to a later visit (--visit 2 "
                             "or more); visit 1 is the apartment as generated")
        if drive and scene_seed is None:
            raise InputError(f"{map_file} records no scene seed to drive in (a map of a recording): pass --scene "
                             "SEED, or plan only (the default)")
        if (drive is False or scene_seed is None) and occupancy != "mapped":
            raise InputError("--occupancy truth needs the simulator: it applies only when driving (--drive)")
        emb = create_embedder(embedder, **({"path": str(embedder_path)} if embedder_path else {}))
        ver_kw = {"embedder": emb} if verifier == "offline" else {}
        retriever = Retriever(cmap, emb, create_verifier(verifier, **ver_kw), RetrievalConfig(distance=distance))
        con = make_console(stderr=True)
        from capnav.retrieval.query import parse_goals

        goals = parse_goals(instruction, retriever.embedder)
        if search and len(goals) > 1:
            raise InputError(f"--search takes one goal; {instruction!r} names {len(goals)} ({goals[0].text!r}, ...)")
        if drive is False or scene_seed is None:
            if len(goals) == 1:
                _plan_only(con, cmap, retriever, instruction, given, out, map_file, through_unknown)
            else:
                _plan_legs(con, cmap, retriever, goals, given, out, through_unknown)
            return
        from capnav.io.rosmap import write_ros_map
        from capnav.pipeline.drive import random_start, run_instruction
        from capnav.sim import Simulator

        legs = []
        stopped = ""
        with Simulator.from_seed(int(scene_seed), visit=visit, changes=spec, change_seed=change_seed) as sim:
            if given is None and cmap.trajectory is not None and len(cmap.trajectory):
                from capnav.planning.on_map import camera_start

                given, where = camera_start(cmap.trajectory)
                con.print(f"start: {where}", highlight=False)
            pose = given or random_start(sim, seed)
            agent = sim.spawn_agent(*pose)
            if search:
                ok = _search(con, cmap, retriever, instruction, agent, out, budget_m, budget_s)
                if not ok:
                    raise typer.Exit(1)
                return
            for k, goal in enumerate(goals):
                if len(goals) > 1:
                    con.print(f"[bold]goal {k + 1} of {len(goals)}[/]: {goal.text}", highlight=False)
                res = run_instruction(cmap, sim, retriever, instruction if len(goals) == 1 else goal, None, occupancy,
                                      out_dir=out, stem="navigate" if k == 0 else f"navigate_leg{k + 1}", agent=agent)
                legs.append(res)
                q, nav = res.query, res.nav
                con.print(f"chosen: {q.chosen.id if q.chosen else '-'} {q.chosen.caption if q.chosen else ''}",
                          highlight=False)
                con.print(f"why: {q.reason}", highlight=False)
                if nav is not None:
                    colour = "green" if nav.reached else "red"
                    con.print(f"[{colour}]{'reached' if nav.reached else 'not reached'}[/]: {nav.reason}; "
                              f"path {nav.path_length:.2f} m, {nav.replans} replans", highlight=False)
                if not res.reached:
                    if k + 1 < len(goals):
                        stopped = _stopped(k, len(goals), goal.text, "not reached")
                    break
        if len(goals) > 1 and legs[0].json is not None:
            _add_legs(legs[0].json, [r.to_dict() for r in legs], len(goals), stopped,
                      all(r.reached for r in legs) and len(legs) == len(goals))
        pgm, yml = write_ros_map(cmap.occupancy, out / "navigate_map.yaml")
        con.print("\n".join(str(p) for r in legs for p in (r.png, r.json) if p is not None) + f"\n{yml} (+ {pgm.name})",
                  highlight=False)
        if stopped:
            con.print(f"[red]stopped[/]: {stopped}", highlight=False)
        if not (all(r.reached for r in legs) and len(legs) == len(goals)):
            raise typer.Exit(1)


def _search(con: Console, cmap: CapNavMap, retriever: Retriever, instruction: str, agent: object, out: Path,
            budget_m: float, budget_s: float | None) -> bool:
    """``--search``: ask the map, go and look, search if needed; each step's reason on the console
    and in navigate.json (``search.steps``); ``goal`` is the pose the robot stopped at when found."""
    import numpy as np

    from capnav.explore.search import SearchConfig, search_goal
    from capnav.io.rosmap import write_ros_map
    from capnav.perception import create_detector
    from capnav.viz.topdown import write_navigation

    x, y, yaw = (float(v) for v in agent.pose)  # type: ignore[attr-defined]
    q, res = search_goal(cmap, retriever, instruction, agent, create_detector("sim"),
                         SearchConfig(budget_m=budget_m, budget_s=budget_s))
    for k, step in enumerate(res.steps):
        colour = {"found": "green", "not found": "red"}.get(step.action, "default")
        con.print(f"[{colour}]{k + 1}. {step.action}[/] (driven {step.driven_m:.1f} m): {step.reason}",
                  highlight=False)
    end = tuple(float(v) for v in agent.pose)  # type: ignore[attr-defined]
    traj = np.asarray(getattr(agent, "trajectory", [(x, y, yaw)]), dtype=np.float64)[:, :2]
    title = f'"{instruction}" --search: {"found" if res.found else "NOT found"}, drove {res.driven_m:.1f} m'
    png, js = write_navigation(out, "navigate", cmap.occupancy, cmap.objects, res.chosen_object, None, traj,
                               (x, y, yaw), end, title, goal=end if res.found else None,  # type: ignore[arg-type]
                               instruction=instruction, ok=res.found, reason=res.reason, retrieval=q.to_dict(),
                               search=res.to_dict())
    pgm, yml = write_ros_map(cmap.occupancy, out / "navigate_map.yaml")
    con.print(f"{png}\n{js}\n{yml} (+ {pgm.name})", highlight=False)
    return res.found


def _stopped(k: int, n: int, text: str, what: str) -> str:
    return f"goal {k + 1} of {n} ({text!r}) {what}, so the {n - k - 1} goal(s) after it were not tried"


def _add_legs(path: Path, legs: list[dict[str, object]], total: int, stopped: str, all_ok: bool) -> None:
    """navigate.json of a sequence: the first leg's fields as for one goal, and every leg in
    ``legs`` (each with its own goal, path and ``ok``); ``ok`` there means every leg succeeded."""
    import json

    from capnav.core.atomic import write_json

    data = json.loads(path.read_text(encoding="utf-8"))
    data.update({"ok": all_ok, "legs": legs, "goals_total": total, "stopped": stopped})
    write_json(path, data)


def _plan_legs(con: Console, cmap: CapNavMap, retriever: Retriever, goals: list[ParsedQuery],
               start: tuple[float, float, float] | None, out: Path, through_unknown: bool = False) -> None:
    """Several goals on a map alone: each leg planned from the goal pose of the one before;
    navigate.json holds the first leg as for one goal and every leg in ``legs``."""
    from capnav.planning.on_map import navigate_on_map, write_outputs

    navs = []
    stopped = ""
    for k, goal in enumerate(goals):
        nav = navigate_on_map(cmap, retriever, goal, start, through_unknown=through_unknown)
        navs.append(nav)
        q = nav.query
        con.print(f"[bold]goal {k + 1} of {len(goals)}[/]: {goal.text}", highlight=False)
        con.print(f"chosen: {q.chosen.id if q.chosen else '-'} {q.chosen.caption if q.chosen else ''}", highlight=False)
        con.print(f"[{'green' if nav.ok else 'red'}]{'planned' if nav.ok else 'no plan'}[/]: {nav.reason}",
                  highlight=False)
        if not nav.ok or nav.goal is None:
            if k + 1 < len(goals):
                stopped = _stopped(k, len(goals), goal.text, "has no plan")
            break
        start = (float(nav.goal.xy[0]), float(nav.goal.xy[1]), float(nav.goal.yaw))
    files = [write_outputs(nav, cmap, out, "navigate" if k == 0 else f"navigate_leg{k + 1}")
             for k, nav in enumerate(navs)]
    all_ok = len(navs) == len(goals) and all(n.ok for n in navs)
    _add_legs(files[0]["json"], [n.to_dict() for n in navs], len(goals), stopped, all_ok)
    con.print("\n".join(str(f[k]) for f in files for k in ("json", "png")), highlight=False)
    con.print("\n".join(str(files[0][k]) for k in ("yaml", "pgm")), highlight=False)
    if stopped:
        con.print(f"[red]stopped[/]: {stopped}", highlight=False)
    if not all_ok:
        raise typer.Exit(1)


def _plan_only(con: Console, cmap: CapNavMap, retriever: Retriever, instruction: str,
               start: tuple[float, float, float] | None, out: Path, map_file: Path, through_unknown: bool = False
               ) -> None:
    """No simulator: the goal pose and path on the map, written for a robot stack; exit 1 when there is none."""
    from capnav.planning.on_map import navigate_on_map, write_outputs

    nav = navigate_on_map(cmap, retriever, instruction, start, through_unknown=through_unknown)
    q = nav.query
    con.print(f"start: ({nav.start[0]:.2f}, {nav.start[1]:.2f}, yaw {nav.start[2]:.2f}) from {nav.start_source}",
              highlight=False)
    con.print(f"chosen: {q.chosen.id if q.chosen else '-'} {q.chosen.caption if q.chosen else ''}", highlight=False)
    con.print(f"why: {q.reason}", highlight=False)
    if nav.goal is not None:
        g = nav.goal
        con.print(f"goal pose: x {g.xy[0]:.2f}, y {g.xy[1]:.2f}, yaw {g.yaw:.2f} (map frame of {map_file.name})",
                  highlight=False)
    con.print(f"[{'green' if nav.ok else 'red'}]{'planned' if nav.ok else 'no plan'}[/]: {nav.reason}",
              highlight=False)
    files = write_outputs(nav, cmap, out)
    con.print("\n".join(str(files[k]) for k in ("json", "png", "yaml", "pgm")), highlight=False)
    if not nav.ok:
        raise typer.Exit(1)
