"""Limits of values several parts of CapNav take (image size, seeds, counts): defined once so the
simulator, the benchmark, the demo and every command accept and refuse the same values."""

from __future__ import annotations

from capnav.core.errors import InputError

IMAGE_MIN, IMAGE_MAX = 16, 4096  # pixels, width and height alike
HFOV_MIN, HFOV_MAX = 10.0, 150.0  # degrees


def check_image_size(width: int, height: int) -> None:
    if not (IMAGE_MIN <= width <= IMAGE_MAX and IMAGE_MIN <= height <= IMAGE_MAX):
        raise InputError(f"image size must be within {IMAGE_MIN}..{IMAGE_MAX} pixels, got {width}x{height}")


def check_count(name: str, value: int | None, optional: bool = False) -> None:
    """A count (frames, scenes, steps, ...) is a whole number >= 1; ``None`` means "no limit" when optional."""
    if value is None and optional:
        return
    if value is None or isinstance(value, bool) or int(value) != value or value < 1:
        raise InputError(f"{name} must be a whole number >= 1, got {value!r}")


def check_seed(name: str, value: int) -> None:
    if isinstance(value, bool) or int(value) != value or value < 0:
        raise InputError(f"{name} must be a whole number >= 0, got {value!r}")
