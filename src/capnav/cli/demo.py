"""``capnav demo``: the whole loop on one generated apartment, ending in an HTML/Markdown report."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from capnav.cli.options import Height, MaxFrames, Seed, Width, check_output_dir, check_verifier, on_interrupt


def register(app: typer.Typer) -> None:
    @app.command()
    def demo(
        out: Annotated[Path, typer.Option("--out", "-o", help="output folder (map, pictures, report)")] = Path(
            "runs/demo"),
        seed: Seed = 0,
        instruction: Annotated[list[str] | None, typer.Option(
            "--instruction", "-i", help="your own instruction (repeatable); default: one generated per kind")] = None,
        width: Width = 320,
        height: Height = 240,
        max_frames: MaxFrames = None,
        verifier: Annotated[str, typer.Option(help="verification back-end (offline, none, gemini, openai, ...)")
                            ] = "offline",
    ) -> None:
        """Explore a procedural apartment, map it, caption its objects, answer instructions, navigate, report."""
        from capnav.demo.run import DemoConfig, run_demo

        check_output_dir(out, "--out")
        check_verifier(verifier)  # before minutes of mapping and captioning, not after
        on_interrupt(f"the files already in {out} are complete; the report was not written")
        run_demo(DemoConfig(seed=seed, out=out, width=width, height=height, max_frames=max_frames,
                            instructions=tuple(instruction or ()), verifier=verifier))
