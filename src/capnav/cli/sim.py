"""``capnav sim``: generate an apartment and write its exploration pass as a dataset folder."""

from __future__ import annotations

from pathlib import Path

import typer

from capnav.cli.options import Height, MaxFrames, Seed, Stride, Width, check_output_dir, on_interrupt
from capnav.core.limits import HFOV_MAX, HFOV_MIN


def register(app: typer.Typer) -> None:
    @app.command("sim")
    def sim_cmd(
        out: Path = typer.Option(..., "--out", "-o", help="dataset folder to create"),
        seed: Seed = 0,
        frames: MaxFrames = None,
        stride: Stride = 1,
        width: Width = 320,
        height: Height = 240,
        hfov: float = typer.Option(90.0, "--hfov", min=HFOV_MIN, max=HFOV_MAX,
                                   help="horizontal field of view (degrees)"),
        rooms: int | None = typer.Option(None, "--rooms", min=3, max=7,
                                         help="number of rooms 3..7 (default: from the seed)"),
        furniture: str = typer.Option("primitives", "--furniture", help="primitives | sh3d (after `capnav assets`)"),
        assets_dir: Path | None = typer.Option(None, "--assets-dir", help="mesh cache of `capnav assets --dir`"),
        depth_noise: bool = typer.Option(False, "--depth-noise", help="consumer RGB-D depth noise (seeded)"),
        surface_items: bool = typer.Option(False, "--surface-items",
                                           help="put cups, bottles, books, vases, bowls and laptops on tables, "
                                                "counters and shelves (in manifest.json with what they stand on)"),
        overwrite: bool = typer.Option(False, "--overwrite", help="replace an existing dataset folder (kept "
                                                                  "until the new one is complete)"),
    ) -> None:
        """Write a posed RGB-D dataset (with manifest.json and topdown.png) for one apartment."""
        from rich.console import Console

        check_output_dir(out, "--out", must_be_empty=True, overwrite=overwrite)
        on_interrupt(f"{out} was left as it was (the new dataset is built beside it and swapped in only when "
                     "complete)")

        from capnav.sim.record import record_dataset

        summary = record_dataset(seed=seed, out=out, frames=frames, stride=stride, width=width, height=height,
                                 hfov=hfov, rooms=rooms, furniture=furniture, depth_noise=depth_noise,
                                 overwrite=overwrite, assets_dir=assets_dir, surface_items=surface_items)
        Console().print(summary, markup=False, highlight=False)
