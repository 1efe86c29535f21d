"""``capnav query MAP "instruction" [--robot X,Y] [--json]``: which object, why, and the runners-up;
for a request of several goals ("the fridge, then the sofa") every goal in turn, stopping at the
first that is not found."""

from __future__ import annotations

import json
from pathlib import Path

import typer

from capnav.core.errors import InputError


def parse_xy(text: str | None) -> tuple[float, float] | None:
    if text is None:
        return None
    try:
        x, y = (float(v) for v in text.split(","))
    except ValueError:
        raise InputError(f"--robot must be X,Y in metres (e.g. 1.5,2.0), got {text!r}") from None
    return (x, y)


def register(app: typer.Typer) -> None:
    @app.command("query")
    def query_cmd(
        map_path: Path = typer.Argument(..., help="a captioned map (see `capnav caption`)"),
        instruction: str = typer.Argument(..., help='e.g. "go to the white sofa with curved edges"'),
        robot: str | None = typer.Option(None, "--robot", help="robot position X,Y in metres"),
        as_json: bool = typer.Option(False, "--json", help="print the result as JSON"),
        verifier: str = typer.Option("offline", help="offline | none | gemini | openai | hf-local"),
        heuristic: bool = typer.Option(True, "--heuristic/--no-heuristic",
                                       help="attribute heuristic; --no-heuristic is the paper's ablation"),
        embedder: str = typer.Option("auto", help="auto (the map's default model) or a backend name"),
        embedder_path: Path | None = typer.Option(None, help="local model folder for non-default embedders"),
        distance: str = typer.Option("walking", help="how 'closest' measures: walking (along the map's floor) or "
                                                     "straight (the paper's eq. 17 grid distance)"),
    ) -> None:
        """Retrieve the object an instruction describes (paper 3.4); exit code 1 when nothing matches
        (0 with --json, whose payload says "found": false)."""
        from concurrent.futures import ThreadPoolExecutor

        from capnav.cli.options import check_model_folder, check_verifier
        from capnav.language import create_embedder
        from capnav.language.embedder import EMBEDDERS
        from capnav.language.onnx_embedder import MINILM_MODEL_ID

        xy = parse_xy(robot)
        check_verifier(verifier)
        if embedder != "auto":
            check_model_folder("--embedder", embedder, embedder_path, "--embedder-path", EMBEDDERS.required(embedder))
        kw = {"path": embedder_path} if embedder != "auto" and embedder_path is not None else {}
        # The embedder's ONNX session (~0.5 s, built with the GIL released) is made while the
        # retrieval code imports and the map loads: a one-shot query's wall time on two cores.
        with ThreadPoolExecutor(1) as pool:
            pending = pool.submit(create_embedder, "minilm" if embedder == "auto" else embedder, **kw)
            from capnav.retrieval.query import prefetch_parser, validate_instruction

            prefetch_parser(validate_instruction(instruction))  # a sentence's parser loads meanwhile
            from capnav.io.mapfile import load_map
            from capnav.retrieval import RetrievalConfig, Retriever, create_verifier
            from capnav.retrieval.sequence import query_goals

            cmap = load_map(map_path, voxels=False)  # retrieval reads objects and occupancy only
            from capnav.mapping.embeddings import check_embeddings

            check_embeddings(cmap, str(map_path))  # all-zero or non-unit vectors: refused, not answered 0.000
            if not cmap.objects:  # not "no captions": captioning an empty map leaves it empty
                raise InputError(f"{map_path} has no objects, so nothing can be found in it (`capnav map` said "
                                 "why when it wrote the map: e.g. nothing detected, or too few frames)")
            if embedder == "auto":
                models = {o.embedding_model for o in cmap.objects if o.embedding_model}
                if not models:
                    raise InputError(f"{map_path} has no captions/embeddings: run `capnav caption {map_path} "
                                     "--dataset DIR` first")
                if models != {MINILM_MODEL_ID}:
                    raise InputError(f"{map_path} was embedded with {sorted(models)}; pass --embedder and "
                                     "--embedder-path for that model")
            emb = pending.result()
        robot_note = ""
        if xy is not None:  # off the map: an error, as for navigate; in an obstacle: the nearest free cell
            from capnav.planning.position import place_robot

            xy, robot_note = place_robot(cmap.occupancy, xy, "--robot")
        cfg = RetrievalConfig(use_verifier=verifier != "none", use_attribute_heuristic=heuristic, distance=distance)
        seq = query_goals(Retriever(cmap, emb, create_verifier(verifier), cfg), instruction, robot_xy=xy)
        if as_json:
            typer.echo(json.dumps(seq.to_dict() | ({"robot_note": robot_note} if robot_note else {}), indent=2))
        else:
            if robot_note:
                typer.echo(f"note: {robot_note}", err=True)
            for k, res in enumerate(seq.results):
                if len(seq.goals) > 1:
                    typer.echo(f"goal {k + 1} of {len(seq.goals)}: {seq.goals[k]}")
                _print(res)
            if seq.stopped:
                typer.echo(f"stopped: {seq.stopped}")
        # Answered "not found": exit code 1, as `capnav navigate` when not reached. With --json the
        # answer is in the payload ("found": false) and a printed answer exits 0, so that scripts
        # that read JSON (and treat a non-zero exit as a failure to answer) see a refusal as one.
        if not seq.found and not as_json:
            raise typer.Exit(1)


def _print(res: object) -> None:
    from rich.table import Table

    from capnav.core.console import make_console
    from capnav.retrieval.result import QueryResult

    assert isinstance(res, QueryResult)
    con = make_console()
    if res.chosen is None:
        con.print(f"[bold red]not found[/]: {res.instruction!r}", highlight=False)
    else:
        o = res.chosen
        con.print(f"[bold green]object {o.id}[/] ({o.label}) at x={o.position[0]:.2f}, y={o.position[1]:.2f} m",
                  highlight=False)
        con.print(f"  caption: {o.caption}", highlight=False)
        dist = f", {res.distance_m:.2f} m from the robot" if res.distance_m is not None else ""
        con.print(f"  similarity {res.score:.3f}, mode {res.mode}"
                  f"{', predicate ' + res.predicate if res.predicate else ''}{dist}", highlight=False)
    con.print(f"  why: {res.reason}", highlight=False)
    if res.ranked:
        t = Table("id", "label", "score", "caption", "why not", title="runners-up (decision order)",
                  title_justify="left")
        for k, (obj, s) in enumerate(res.ranked):
            why = res.details[k]["why"] if k < len(res.details) else ""
            t.add_row(str(obj.id), obj.label, f"{s:.3f}", obj.caption or "", why)
        con.print(t)
    con.print("  timings: " + ", ".join(f"{k} {v * 1e3:.1f} ms" for k, v in res.timings.items()), highlight=False)
