"""``capnav demo``: the whole loop on one generated apartment, ending in an HTML/Markdown report."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer


def register(app: typer.Typer) -> None:
    @app.command()
    def demo(
        out: Annotated[Path, typer.Option("--out", "-o", help="output folder (map, pictures, report)")] = Path(
            "runs/demo"),
        seed: Annotated[int, typer.Option(help="apartment / run seed")] = 0,
        instruction: Annotated[list[str] | None, typer.Option(
            "--instruction", "-i", help="your own instruction (repeatable); default: one generated per kind")] = None,
        width: Annotated[int, typer.Option(help="camera width (pixels)")] = 320,
        height: Annotated[int, typer.Option(help="camera height (pixels)")] = 240,
        max_frames: Annotated[int | None, typer.Option(help="use at most this many exploration frames")] = None,
        verifier: Annotated[str, typer.Option(help="verification back-end (offline, none, gemini, openai, ...)")
                            ] = "offline",
    ) -> None:
        """Explore a procedural apartment, map it, caption its objects, answer instructions, navigate, report."""
        from capnav.demo.run import DemoConfig, run_demo

        run_demo(DemoConfig(seed=seed, out=out, width=width, height=height, max_frames=max_frames,
                            instructions=tuple(instruction or ()), verifier=verifier))
