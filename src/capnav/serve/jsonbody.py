"""Reading a JSON request body within bounds: nesting depth and element count are checked before
and after parsing, so a body of a few thousand ``[`` is a 400 naming the limit instead of a
``RecursionError`` in the decoder."""

from __future__ import annotations

import json
import re
from typing import Any

import numpy as np

from capnav.core.errors import InputError

_STRING = re.compile(rb'"(?:[^"\\]|\\.)*"', re.DOTALL)
_OPEN = np.zeros(256, np.int8)
_OPEN[[ord("["), ord("{")]] = 1
_OPEN[[ord("]"), ord("}")]] = -1


def nesting_depth(raw: bytes) -> int:
    """The deepest ``[``/``{`` nesting of a JSON text (brackets inside strings do not count)."""
    bare = _STRING.sub(b'""', raw)
    if not bare:
        return 0
    steps = _OPEN[np.frombuffer(bare, np.uint8)].astype(np.int32)
    return int(np.cumsum(steps).max(initial=0))


def count_elements(value: Any) -> int:
    """Values in a parsed JSON document (each container, key and scalar counts one)."""
    n, stack = 0, [value]
    while stack:
        v = stack.pop()
        n += 1
        if isinstance(v, dict):
            n += len(v)  # the keys
            stack.extend(v.values())
        elif isinstance(v, list):
            stack.extend(v)
    return n


def parse_bounded(raw: bytes, max_depth: int, max_elements: int) -> Any:
    """``json.loads(raw)`` with the two bounds; ``InputError`` (a 400) naming the one exceeded."""
    depth = nesting_depth(raw)
    if depth > max_depth:
        raise InputError(f"the JSON body nests {depth} levels deep; at most {max_depth} are accepted")
    try:
        value = json.loads(raw)
    except (ValueError, RecursionError) as e:
        raise InputError(f"the body is not valid JSON ({e})") from None
    n = count_elements(value)
    if n > max_elements:
        raise InputError(f"the JSON body has {n} elements; at most {max_elements} are accepted")
    return value
