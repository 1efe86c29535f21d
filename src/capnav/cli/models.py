"""``capnav models install NAME [--from DIR]`` / ``capnav models list``: pretrained detector files on this machine."""

from __future__ import annotations

from pathlib import Path

import typer


def register(app: typer.Typer) -> None:
    models = typer.Typer(help="Install and list the pretrained models of the real detectors (checksummed).",
                         no_args_is_help=True)
    app.add_typer(models, name="models")
    root_help = "model folder (default $CAPNAV_MODELS, else ~/.cache/capnav/models)"

    @models.command("install")
    def install_cmd(
        name: str = typer.Argument(..., help="model name (capnav models list shows them)"),
        source: Path | None = typer.Option(None, "--from", help="copy the files from this local folder instead of "
                                                                "downloading them from their public source"),
        dir: Path | None = typer.Option(None, "--dir", help=root_help),
    ) -> None:
        """Copy or download a model's files, check each sha256 against the pinned value, record licence and source."""
        from capnav.core.console import make_console
        from capnav.perception.model_store import install, spec

        out = install(name, root=dir, source_dir=source)
        make_console().print(f"{name} installed in {out} (licence: {spec(name).licence})", markup=False,
                             highlight=False)

    @models.command("list")
    def list_cmd(dir: Path | None = typer.Option(None, "--dir", help=root_help)) -> None:
        """Known models, where they go and whether their installed files check out."""
        from capnav.core.console import make_console
        from capnav.perception.model_store import installed

        con = make_console()
        for row in installed(dir):
            con.print(f"{row['name']:<28} {row['status']:<14} {row['folder']}\n    {row['description']}; "
                      f"licence: {row['licence']}", markup=False, highlight=False)
