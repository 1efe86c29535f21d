"""``capnav navigate MAP --scene SEED "instruction"``: retrieve, plan with A*, drive, draw."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer


def register(app: typer.Typer) -> None:
    @app.command()
    def navigate(
        map_file: Annotated[Path, typer.Argument(help="map file with captions (capnav map + capnav caption)")],
        instruction: Annotated[str, typer.Argument(help='what to go to, e.g. "the white sofa with curved arms"')],
        scene: Annotated[int | None, typer.Option(
            "--scene", help="apartment seed to drive in (default: the seed recorded in the map)")] = None,
        start: Annotated[str | None, typer.Option(help="start pose X,Y[,YAW] (m, rad); default: seeded random")
                         ] = None,
        seed: Annotated[int, typer.Option(help="seed of the random start")] = 0,
        episode: Annotated[Path | None, typer.Option(
            help="episode file (capnav eval): scene and start pose from its episode --episode-id")] = None,
        episode_id: Annotated[str | None, typer.Option(help="episode id in --episode (default: the first)")
                              ] = None,
        out: Annotated[Path, typer.Option("--out", "-o", help="folder for navigate.png / navigate.json")] = Path(
            "runs/navigate"),
        occupancy: Annotated[str, typer.Option(help="plan on the 'mapped' occupancy or the simulator's 'truth'")
                             ] = "mapped",
        embedder: Annotated[str, typer.Option(help="text embedder backend (must match the map's captions)")
                            ] = "minilm",
        embedder_path: Annotated[Path | None, typer.Option(help="model folder for folder-based embedders")
                                 ] = None,
        verifier: Annotated[str, typer.Option(help="verification backend: offline, none, gemini, openai, ...")
                            ] = "offline",
    ) -> None:
        """Go to the object an instruction describes, in a simulated apartment; writes PNG + JSON."""
        from rich.console import Console

        from capnav.core.errors import InputError
        from capnav.io.mapfile import load_map
        from capnav.language import create_embedder
        from capnav.planning.instruction import (
            OCCUPANCY_KINDS,
            episode_start,
            parse_pose,
            random_start,
            run_instruction,
        )
        from capnav.retrieval import Retriever, create_verifier
        from capnav.sim import Simulator

        if occupancy not in OCCUPANCY_KINDS:  # fail before the slow loading below
            raise InputError(f"occupancy must be one of {', '.join(OCCUPANCY_KINDS)}, got {occupancy!r}")
        given = parse_pose(start) if start else None
        ep_scene = None
        if episode is not None:
            ep_scene, ep_pose = episode_start(episode, episode_id)
            given = given or ep_pose
        cmap = load_map(map_file)
        scene_seed = next((s for s in (scene, ep_scene, cmap.meta.get("scene_seed")) if s is not None), None)
        if scene_seed is None:
            raise InputError(f"{map_file} records no scene seed: pass --scene SEED")
        emb = create_embedder(embedder, **({"path": str(embedder_path)} if embedder_path else {}))
        ver_kw = {"embedder": emb} if verifier == "offline" else {}
        retriever = Retriever(cmap, emb, create_verifier(verifier, **ver_kw))
        with Simulator.from_seed(int(scene_seed)) as sim:
            pose = given or random_start(sim, seed)
            res = run_instruction(cmap, sim, retriever, instruction, pose, occupancy, out_dir=out)
        con = Console(stderr=True)
        q, nav = res.query, res.nav
        con.print(f"chosen: {q.chosen.id if q.chosen else '-'} {q.chosen.caption if q.chosen else ''}", highlight=False)
        con.print(f"why: {q.reason}", highlight=False)
        if nav is not None:
            colour = "green" if nav.reached else "red"
            con.print(f"[{colour}]{'reached' if nav.reached else 'not reached'}[/]: {nav.reason}; "
                      f"path {nav.path_length:.2f} m, {nav.replans} replans", highlight=False)
        con.print(f"{res.png}\n{res.json}", highlight=False)
        if not res.reached:
            raise typer.Exit(1)
