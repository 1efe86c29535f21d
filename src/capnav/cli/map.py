"""``capnav map DATASET -o MAP``: build a CapNav map from a posed RGB-D dataset folder."""

from __future__ import annotations

from pathlib import Path

import typer


def register(app: typer.Typer) -> None:
    @app.command("map")
    def map_cmd(
        dataset: Path = typer.Argument(..., help="dataset folder (capnav-rgbd format)"),
        output: Path = typer.Option(..., "-o", "--output", help="map file to write (e.g. apt0.capnav)"),
        detector: str = typer.Option("sim", help="detector backend"),
        noise: str = typer.Option("default", help="sim detector noise: default, hard, oracle"),
        seed: int = typer.Option(0, help="seed of the detector's noise"),
        encoder: str = typer.Option("label-embedding", help="dense feature encoder backend"),
        embedder: str = typer.Option("minilm", help="text embedder of the label-embedding encoder"),
        max_frames: int | None = typer.Option(None, help="use only the first N frames"),
        strict: bool = typer.Option(False, help="stop at the first bad frame instead of skipping it"),
        progress: bool = typer.Option(True, help="show a progress bar"),
    ) -> None:
        """Detect, fuse the semantic voxel map, track objects and write the map file."""
        from rich.console import Console

        from capnav.io.dataset import DatasetReader
        from capnav.io.mapfile import save_map
        from capnav.language import create_embedder
        from capnav.mapping import MapperConfig, map_dataset
        from capnav.perception import create_detector, create_encoder

        reader = DatasetReader(dataset)  # fail on a bad folder before loading any model
        det = create_detector(detector, noise=noise, seed=seed) if detector == "sim" else create_detector(detector)
        enc = create_encoder(encoder, embedder=create_embedder(embedder))
        cfg = MapperConfig(on_bad_frame="raise" if strict else "skip")
        cmap = map_dataset(reader, det, enc, cfg, max_frames=max_frames, progress=progress)
        save_map(cmap, output)
        con = Console(stderr=True)
        m = cmap.meta
        fps = m["frames_used"] / m["mapping_seconds"] if m["mapping_seconds"] else float("nan")
        con.print(f"{output}: {len(cmap.objects)} objects, {len(cmap.voxels)} voxels, "
                  f"{m['frames_used']} frames ({fps:.1f} frames/s), detector {det.id}")
        for s in m["frames_skipped"]:
            con.print(f"[yellow]skipped frame {s['frame']}:[/] {s['reason']}", highlight=False)
