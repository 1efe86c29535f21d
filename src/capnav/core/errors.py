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
