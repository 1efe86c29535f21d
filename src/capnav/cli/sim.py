"""``capnav sim``: generate an apartment and write its exploration pass as a dataset folder."""

from __future__ import annotations

from pathlib import Path

import typer

from capnav.cli.options import Height, Hfov, MaxFrames, Seed, Stride, Width, check_output_dir, on_interrupt


def register(app: typer.Typer) -> None:
    @app.command("sim")
    def sim_cmd(
        out: Path = typer.Option(..., "--out", "-o", help="dataset folder to create"),
        seed: Seed = 0,
        frames: MaxFrames = None,
        stride: Stride = 1,
        width: Width = 320,
        height: Height = 240,
        hfov: Hfov = 90.0,
        rooms: int | None = typer.Option(None, "--rooms", min=3, max=7,
                                         help="number of rooms 3..7 (default: from the seed)"),
        furniture: str = typer.Option("primitives", "--furniture", help="primitives | sh3d (after `capnav assets`)"),
        assets_dir: Path | None = typer.Option(None, "--assets-dir", help="mesh cache of `capnav assets --dir`"),
        depth_noise: bool = typer.Option(False, "--depth-noise", help="consumer RGB-D depth noise (seeded)"),
        surface_items: bool = typer.Option(False, "--surface-items",
                                           help="put cups, bottles, books, vases, bowls and laptops on tables, "
                                                "counters and shelves (in manifest.json with what they stand on)"),
        visit: int = typer.Option(1, "--visit", min=1, max=100,
                                  help="1: the apartment as generated; 2 or more: the same apartment after "
                                       "--changes (listed in manifest.json with old and new poses)"),
        changes: str = typer.Option("moved=3,removed=2,added=2", "--changes",
                                    help="changes of a later --visit: moved=N,removed=N,added=N,hidden=N "
                                         "(hidden: carried into a room the visit never enters)"),
        change_seed: int = typer.Option(0, "--change-seed", min=0, help="seed of the changes (default 0)"),
        frame_offset: str | None = typer.Option(
            None, "--frame-offset", metavar="X,Y,YAW",
            help="write the poses in a world frame shifted by X,Y metres and turned YAW degrees (a robot "
                 "started elsewhere on another day; `capnav map --update` registers the recordings)"),
        export: str | None = typer.Option(None, "--export", help="write the recording in another layout instead: "
                                                                  "tum | open3d | 3dmatch | scannet (read back by "
                                                                  "`capnav import auto`)"),
        tilt: str | None = typer.Option(None, "--tilt", metavar="ROLL,PITCH,YAW",
                                        help="with --export: turn the recording's world by these angles (degrees), "
                                             "so an importer has to find up by itself"),
        overwrite: bool = typer.Option(False, "--overwrite", help="replace an existing dataset folder (kept "
                                                                  "until the new one is complete)"),
    ) -> None:
        """Write a posed RGB-D dataset (with manifest.json and topdown.png) for one apartment, or with --export
        the same recording in another tool's layout."""
        from capnav.core.console import make_console
        from capnav.core.errors import InputError
        from capnav.sim.changes import ChangeSpec

        spec = ChangeSpec.parse(changes) if visit > 1 else None
        offset = None
        if frame_offset is not None:
            try:
                ox, oy, oyaw = (float(v) for v in frame_offset.split(","))
            except ValueError:
                raise InputError(f"--frame-offset must be X,Y,YAW (metres, metres, degrees), got "
                                 f"{frame_offset!r}") from None
            offset = (ox, oy, oyaw)
        check_output_dir(out, "--out", must_be_empty=True, overwrite=overwrite)
        on_interrupt(f"{out} was left as it was (the new dataset is built beside it and swapped in only when "
                     "complete)")

        from capnav.sim.record import record_dataset

        summary = record_dataset(seed=seed, out=out, frames=frames, stride=stride, width=width, height=height,
                                 hfov=hfov, rooms=rooms, furniture=furniture, depth_noise=depth_noise,
                                 overwrite=overwrite, assets_dir=assets_dir, surface_items=surface_items,
                                 visit=visit, changes=spec,
                                 change_seed=change_seed, frame_offset=offset, export=export, tilt=tilt)
        make_console().print(summary, markup=False, highlight=False)
