"""The ``capnav`` command. Each sub-command lives in its own module of this package and exposes
``register(app)``; modules are discovered automatically, so adding a command touches one file.

Every command's body runs inside :func:`_guard`: an OS error becomes a ``SystemIOError`` naming the
path and Ctrl-C an ``Interrupted`` saying what was kept, so :func:`main` prints one ``error:`` /
``interrupted:`` line for them as for any ``CapNavError``. Exit codes: 0 answered, 1 not found /
not reached, 2 error (bad input, unwritable output, OS error), 130 interrupted.
"""

from __future__ import annotations

import functools
import importlib
import pkgutil
import sys
from collections.abc import Callable
from typing import Any

import typer

try:  # typer >= 0.20 carries its own copy of click
    from typer._click import exceptions as cx
except ImportError:  # pragma: no cover
    from click import exceptions as cx  # type: ignore[no-redef]

from capnav.core.errors import CapNavError, Interrupted, SystemIOError

app = typer.Typer(
    name="capnav",
    help="CapNav: description-first indoor navigation (map, caption, retrieve, navigate).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


def _flag_type(self: typer.core.TyperOption, ctx: Any) -> str | None:
    """Help shows no ``<bool>`` beside plain on/off flags (``--overwrite``, ``--help``)."""
    return None if self.is_flag else _option_type(self, ctx)


_option_type = typer.core.TyperOption.display_type_rich
typer.core.TyperOption.display_type_rich = _flag_type  # type: ignore[method-assign]


def _load_commands() -> None:
    for mod in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        if mod.name.startswith("_"):
            continue
        module = importlib.import_module(f"{__name__}.{mod.name}")
        register = getattr(module, "register", None)
        if register is not None:
            register(app)
    _guard_all(app, "capnav")


def _guard(name: str, fn: Callable[..., Any]) -> Callable[..., Any]:
    """``fn`` with OS errors and Ctrl-C turned into CapNav errors that say what happened."""

    @functools.wraps(fn)
    def run(*args: Any, **kwargs: Any) -> Any:
        from capnav.cli.options import describe_os_error, interrupt_note, reset_interrupt_note

        reset_interrupt_note()
        try:
            return fn(*args, **kwargs)
        except KeyboardInterrupt:
            raise Interrupted(f"{name}; {interrupt_note()}") from None
        except OSError as e:
            raise SystemIOError(describe_os_error(e)) from e

    return run


def _guard_all(t: typer.Typer, prefix: str) -> None:
    for cmd in t.registered_commands:
        if cmd.callback is not None and not hasattr(cmd.callback, "__wrapped__"):
            name = cmd.name or cmd.callback.__name__.replace("_", "-")
            cmd.callback = _guard(f"{prefix} {name}", cmd.callback)
    for group in t.registered_groups:
        if group.typer_instance is not None:
            _guard_all(group.typer_instance, f"{prefix} {group.name}")


_load_commands()


def _fail(kind: str, message: str, code: int) -> None:
    from rich.markup import escape

    from capnav.core.console import make_console

    colour = "yellow" if code == 130 else "red"
    make_console(stderr=True).print(f"[bold {colour}]{kind}:[/] {escape(message)}", highlight=False)
    sys.exit(code)


def stop_on_sigterm() -> None:
    """Treat SIGTERM (``kill``, a service manager, a CI timeout) like Ctrl-C, so the same clean-up
    runs: ``eval`` terminates its worker processes instead of leaving them running as orphans."""
    import signal

    def _raise(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, _raise)


def main() -> None:
    """Entry point: expected failures become one red line and exit code 2, not a traceback."""
    stop_on_sigterm()
    try:
        code = app(standalone_mode=False)
    except Interrupted as e:
        _fail("interrupted", str(e), 130)
    except CapNavError as e:
        _fail("error", str(e), 2)
    except cx.NoArgsIsHelpError as e:
        print(e.format_message(), file=sys.stderr)
        sys.exit(2)
    except cx.UsageError as e:
        cmd = e.ctx.command_path if e.ctx is not None else "capnav"
        _fail("error", f"{e.format_message()} (see: {cmd} --help)", 2)
    except typer.Abort:
        _fail("interrupted", "capnav; nothing half-written was left behind", 130)
    except cx.ClickException as e:
        _fail("error", e.format_message(), e.exit_code)
    sys.exit(code if isinstance(code, int) else 0)
