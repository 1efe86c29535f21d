"""``capnav map-eval MAP --manifest DATASET/manifest.json``: mapping quality vs the simulator truth."""

from __future__ import annotations

import json
from pathlib import Path

import typer


def register(app: typer.Typer) -> None:
    @app.command("map-eval")
    def map_eval(
        map_file: Path = typer.Argument(..., help="map file written by `capnav map`"),
        manifest: Path = typer.Option(..., help="the scene's manifest.json (simulator truth)"),
        dataset: Path | None = typer.Option(None, help="dataset folder with truth images (default: the "
                                            "manifest's folder) to count in how many frames each object is seen"),
        json_out: Path | None = typer.Option(None, "--json", help="also write the figures as JSON"),
    ) -> None:
        """Print instance precision/recall, duplicates, category accuracy, centroid error, occupancy IoU."""
        from rich.table import Table

        from capnav.cli.options import check_map_scene, check_output_file
        from capnav.core.atomic import write_json
        from capnav.core.console import make_console
        from capnav.eval.map_quality import evaluate_map, truth_for_dataset
        from capnav.io.mapfile import load_map
        from capnav.sim.manifest import SceneManifest

        if json_out is not None:
            check_output_file(json_out, "--json")
        cmap = load_map(map_file)
        man = SceneManifest.load(manifest)
        check_map_scene(cmap.meta, map_file, man.seed, f"--manifest {manifest}")
        data = dataset or manifest.parent
        if dataset is not None or (data / "meta.json").exists():
            from capnav.cli.options import check_map_matches_dataset
            from capnav.core.errors import CapNavError
            from capnav.io.dataset import DatasetReader

            try:
                reader = DatasetReader(data)
            except CapNavError:
                reader = None  # truth_for_dataset says what is missing
            if reader is not None:
                check_map_matches_dataset(cmap.meta, map_file, data, reader)
        seen, occ, note = truth_for_dataset(data, man)
        q = evaluate_map(cmap, man, seen, occ)
        table = Table(title=f"mapping quality: {map_file.name} (scene seed {man.seed})")
        for col in ("metric", "value", "target"):
            table.add_column(col)
        for row in q.rows():
            table.add_row(*row)
        con = make_console()
        con.print(table)
        if note:
            con.print(note, highlight=False)
        if json_out is not None:
            write_json(json_out, json.loads(json.dumps(q.to_dict(), default=float)))
