"""One error hierarchy so the CLI can turn any expected failure into a one-line message."""

from __future__ import annotations


class CapNavError(Exception):
    """Base class of every error CapNav raises on purpose (bad input, missing files, ...)."""


class InputError(CapNavError, ValueError):
    """An argument or input value is invalid (wrong shape, non-finite, out of range)."""


class FrameError(InputError):
    """A frame of a posed RGB-D stream is unusable; ``frame`` names it."""

    def __init__(self, frame: int | str, reason: str) -> None:
        super().__init__(f"frame {frame}: {reason}")
        self.frame = frame
        self.reason = reason


class PoseError(FrameError):
    """A pose is not a rigid camera-to-world transform."""


class DatasetError(CapNavError):
    """A dataset folder is missing, malformed or has a corrupt/missing frame."""


class MapFileError(CapNavError):
    """A map file is truncated, corrupt, of an unknown version or fails validation."""


class ModelError(CapNavError):
    """A model backend could not be loaded or answered off-schema/timeouted."""


class NotFoundError(CapNavError):
    """A query matched nothing above threshold, or a goal is unreachable."""


class OutputError(InputError):
    """An output path cannot be written (unwritable folder, a folder where a file is meant, ...)."""


class SystemIOError(CapNavError):
    """The operating system refused a read or write; the message names the path and the reason."""


class Interrupted(CapNavError):
    """The user pressed Ctrl-C; the message says what was interrupted and what was kept."""


def pip_hint(requirement: str) -> str:
    """The command that installs ``requirement`` into the Python running CapNav, for error messages.

    It names this interpreter (``.venv/bin/python -m pip install ...``), not a bare ``pip``, which in a
    new shell is the system's and refuses with "externally-managed-environment". ``capnav[EXTRA]``
    becomes the checkout's editable install (``-e '.[EXTRA]'``) when CapNav runs from a source tree."""
    import os
    import shlex
    import sys
    from pathlib import Path

    def shown(p: Path) -> str:
        try:
            rel = os.path.relpath(p)
        except ValueError:  # another drive (Windows)
            return str(p)
        return rel if not rel.startswith("..") else str(p)

    python = shown(Path(sys.executable)) if sys.executable else "python3"
    if not python.startswith((os.sep, ".")) and os.sep in python:
        python = f".{os.sep}{python}"
    req = requirement
    root = Path(__file__).resolve().parents[3]
    if requirement.startswith("capnav[") and (root / "pyproject.toml").is_file() and (root / "src" / "capnav").is_dir():
        where = shown(root)
        req = f"-e {shlex.quote(where + requirement[len('capnav'):])}"
    else:
        req = shlex.quote(requirement)
    return f"{shlex.quote(python) if ' ' in python else python} -m pip install {req}"
