"""The one way CapNav's commands make a rich console: on a terminal it wraps to the window; piped into
a file, a pager or another program it never hard-wraps (rich's default there is 80 columns, which
splits paths and captions across lines), so each message stays one line that ``grep`` finds whole."""

from __future__ import annotations

import os
import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rich.console import Console

#: Width used when not on a terminal and ``COLUMNS`` is unset: wide enough that no line is broken;
#: tables still take only the width their cells need.
PIPED_WIDTH = 1000


def make_console(stderr: bool = False) -> Console:
    """A rich console on stdout (or stderr) that wraps only on a terminal."""
    from rich.console import Console

    stream = sys.stderr if stderr else sys.stdout
    try:
        tty = stream.isatty()
    except (AttributeError, ValueError):  # a closed or replaced stream
        tty = False
    if tty:
        return Console(stderr=stderr)
    cols = os.environ.get("COLUMNS", "")
    return Console(stderr=stderr, soft_wrap=True, width=int(cols) if cols.isdigit() else PIPED_WIDTH)
