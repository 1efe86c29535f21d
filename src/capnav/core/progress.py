"""Progress for long work: a rich bar on a terminal, plain periodic lines otherwise (CI, log files),
nothing when disabled."""

from __future__ import annotations

import sys
import time
from collections.abc import Iterable, Iterator
from typing import TypeVar

T = TypeVar("T")

#: Seconds between plain progress lines when stderr is not a terminal.
LOG_EVERY_S = 10.0


def track(items: Iterable[T], description: str, total: int | None = None, enabled: bool = True) -> Iterator[T]:
    """Iterate ``items`` showing progress on stderr (count, rate and ETA)."""
    if not enabled:
        yield from items
        return
    total = total if total is not None else _len(items)
    if not sys.stderr.isatty():
        yield from _plain(items, description, total)
        return
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                  console=Console(stderr=True), transient=False) as prog:
        task = prog.add_task(description, total=total)
        for item in items:
            yield item
            prog.advance(task)


def _plain(items: Iterable[T], description: str, total: int | None) -> Iterator[T]:
    t0 = last = time.monotonic()
    done = 0
    for item in items:
        yield item
        done += 1
        now = time.monotonic()
        if now - last >= LOG_EVERY_S:
            last = now
            print(_line(description, done, total, now - t0), file=sys.stderr, flush=True)
    print(_line(description, done, total, time.monotonic() - t0) + " done", file=sys.stderr, flush=True)


def _line(description: str, done: int, total: int | None, elapsed: float) -> str:
    rate = done / elapsed if elapsed > 0 else 0.0
    of = f"/{total}" if total else ""
    eta = f", about {(total - done) / rate:.0f} s left" if total and rate > 0 and done < total else ""
    pace = f"{rate:.1f}/s" if rate >= 1 or done == 0 else f"{elapsed / done:.1f} s each"
    return f"{description}: {done}{of} in {elapsed:.0f} s ({pace}{eta})"


def _len(items: Iterable[object]) -> int | None:
    try:
        return len(items)  # type: ignore[arg-type]
    except TypeError:
        return None
