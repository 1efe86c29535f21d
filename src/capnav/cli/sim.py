"""``capnav sim``: generate an apartment and write its exploration pass as a dataset folder."""

from __future__ import annotations

from pathlib import Path

import typer


def register(app: typer.Typer) -> None:
    @app.command("sim")
    def sim_cmd(
        seed: int = typer.Option(0, "--seed", help="apartment seed (same seed = same scene and frames)"),
        out: Path = typer.Option(..., "--out", "-o", help="dataset folder to create"),
        frames: int | None = typer.Option(None, "--frames", help="at most this many frames (uniform subsample)"),
        stride: int = typer.Option(1, "--stride", help="keep every k-th frame of the pass"),
        width: int = typer.Option(320, "--width"),
        height: int = typer.Option(240, "--height"),
        hfov: float = typer.Option(90.0, "--hfov", help="horizontal field of view (degrees)"),
        rooms: int | None = typer.Option(None, "--rooms", help="number of rooms 3..7 (default: from the seed)"),
        furniture: str = typer.Option("primitives", "--furniture", help="primitives | sh3d (after `capnav assets`)"),
        assets_dir: Path | None = typer.Option(None, "--assets-dir", help="mesh cache of `capnav assets --dir`"),
        depth_noise: bool = typer.Option(False, "--depth-noise", help="consumer RGB-D depth noise (seeded)"),
        overwrite: bool = typer.Option(False, "--overwrite", help="replace a non-empty output folder"),
    ) -> None:
        """Write a posed RGB-D dataset (with manifest.json and topdown.png) for one apartment."""
        from rich.console import Console

        from capnav.sim.record import record_dataset

        summary = record_dataset(seed=seed, out=out, frames=frames, stride=stride, width=width, height=height,
                                 hfov=hfov, rooms=rooms, furniture=furniture, depth_noise=depth_noise,
                                 overwrite=overwrite, assets_dir=assets_dir)
        Console().print(summary, markup=False, highlight=False)
