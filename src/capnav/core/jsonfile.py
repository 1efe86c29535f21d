"""Reading the JSON files CapNav writes (manifests, episodes, dataset metadata) with one clear error."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from capnav.core.errors import DatasetError


def read_json_object(path: str | Path, what: str) -> dict[str, Any]:
    """The JSON object in ``path``; ``DatasetError`` naming ``what`` and the file when it is missing,
    not JSON, or not an object (a truncated write, a wrong file)."""
    p = Path(path)
    try:
        data = json.loads(p.read_text())
    except FileNotFoundError:
        raise DatasetError(f"{what} not found (missing {p.name}): {p}") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise DatasetError(f"{what} {p} is not valid JSON: {e}") from None
    if not isinstance(data, dict):
        raise DatasetError(f"{what} {p} must hold a JSON object, got {type(data).__name__}")
    return data
