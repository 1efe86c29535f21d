"""Depth images of public RGB-D datasets decoded to float32 metres (0 = invalid).

Each dataset stores depth its own way, and a wrong guess gives a plausible-looking image in the
wrong units, so the encoding is named, never sniffed:

* ``tum``: 16-bit PNG, ``scale`` units per metre (TUM RGB-D: 5000), 0 = no reading.
* ``nyu``: NYU Depth v2's raw Kinect disparity as a binary PGM (``P5``, maxval 65535).
  metres = 351.3 / (1092.5 - raw), kept within 0.3-10 m; raw 0 and raw >= 1084 (2047 is the
  Kinect's "no reading") are invalid. The samples are stored little-endian although the PGM
  format says big-endian (Open3D's NYU reader swaps the bytes after reading big-endian; the
  same result): read big-endian, 97% of the pixels of ``NYU_depth.pgm`` would be invalid.
* ``sun``: SUN RGB-D's 16-bit PNG with the bits rotated: millimetres = (v >> 3) | (v << 13),
  taken as 16 bits.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from capnav.core.errors import InputError

DEPTH_ENCODINGS = ("tum", "nyu", "sun")
_PGM = re.compile(rb"P5\s+(?:#[^\n]*\n\s*)*(\d+)\s+(?:#[^\n]*\n\s*)*(\d+)\s+(?:#[^\n]*\n\s*)*(\d+)\s")


def read_png16(path: Path) -> NDArray[np.uint16]:
    try:
        with Image.open(path) as im:
            if im.mode not in ("I;16", "I;16B", "I;16L", "I"):
                raise InputError(f"depth image {path} has mode {im.mode}, expected 16-bit grey")
            raw = np.asarray(im)
    except FileNotFoundError:
        raise InputError(f"missing depth image {path}") from None
    except (OSError, SyntaxError, ValueError) as e:
        raise InputError(f"corrupt depth image {path}: {e}") from None
    if raw.min(initial=0) < 0 or raw.max(initial=0) > 0xFFFF:
        raise InputError(f"depth image {path} holds values outside 16 bits")
    return raw.astype(np.uint16)


def _nyu_raw(path: Path) -> NDArray[np.uint16]:
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise InputError(f"missing depth image {path}") from None
    except OSError as e:
        raise InputError(f"cannot read depth image {path}: {e}") from None
    m = _PGM.match(data)
    if m is None:
        raise InputError(f"{path} is not a binary PGM (P5) file")
    w, h, maxval = (int(g) for g in m.groups())
    if maxval < 256:
        raise InputError(f"{path} is an 8-bit PGM (maxval {maxval}); NYU raw depth is 16-bit")
    n = w * h * 2
    if len(data) - m.end() < n:
        raise InputError(f"{path} is truncated: {len(data) - m.end()} bytes of samples, expected {n} for {w}x{h}")
    return np.frombuffer(data, dtype="<u2", count=w * h, offset=m.end()).reshape(h, w)


def decode_depth(path: str | Path, encoding: str, scale: float = 5000.0) -> NDArray[np.float32]:
    """Depth image at ``path`` in float32 metres, 0 where invalid; ``encoding`` one of ``DEPTH_ENCODINGS``
    (``scale``: units per metre of ``tum``)."""
    p = Path(path)
    if encoding == "tum":
        if not np.isfinite(scale) or scale <= 0:
            raise InputError(f"depth scale must be > 0 units per metre, got {scale}")
        return (read_png16(p).astype(np.float32) / np.float32(scale)).astype(np.float32)
    if encoding == "sun":
        v = read_png16(p)
        mm = ((v >> 3) | (v << 13)).astype(np.uint16)
        return (mm.astype(np.float32) / np.float32(1000.0)).astype(np.float32)
    if encoding == "nyu":
        raw = _nyu_raw(p).astype(np.float64)
        ok = (raw > 0) & (raw < 1084)
        metres = np.zeros(raw.shape, dtype=np.float64)
        metres[ok] = 351.3 / (1092.5 - raw[ok])
        metres[(metres < 0.3) | (metres > 10.0)] = 0.0
        return metres.astype(np.float32)
    raise InputError(f"unknown depth encoding {encoding!r}; known: {', '.join(DEPTH_ENCODINGS)}")
