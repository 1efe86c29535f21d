"""The ``capnav`` command. Each sub-command lives in its own module of this package and exposes
``register(app)``; modules are discovered automatically, so adding a command touches one file."""

from __future__ import annotations

import importlib
import pkgutil
import sys

import typer

from capnav.core.errors import CapNavError

app = typer.Typer(
    name="capnav",
    help="CapNav: description-first indoor navigation (map, caption, retrieve, navigate).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


def _load_commands() -> None:
    for mod in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        if mod.name.startswith("_"):
            continue
        module = importlib.import_module(f"{__name__}.{mod.name}")
        register = getattr(module, "register", None)
        if register is not None:
            register(app)


_load_commands()


def main() -> None:
    """Entry point: expected failures become one red line and exit code 2, not a traceback."""
    try:
        app()
    except CapNavError as e:
        from rich.console import Console

        Console(stderr=True).print(f"[bold red]error:[/] {e}", highlight=False)
        sys.exit(2)
