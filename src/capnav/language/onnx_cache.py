"""onnxruntime sessions that skip graph optimisation after the first run on a machine.

Optimising a transformer graph is about half of a fresh ``capnav query`` process's model start
(0.48 s of CPU for MiniLM int8, against 0.25 s to load an already optimised copy, same outputs bit
for bit). So the first session saves its optimised graph, as onnxruntime documents for offline
optimisation, and later sessions load that copy with optimisation off.

The copy is saved at ``ORT_ENABLE_EXTENDED``: the level above it adds layout transforms tied to
this CPU. It is keyed by the source model's sha256 and the onnxruntime version, written atomically
with a sidecar holding its own sha256, and checked before use; a missing, stale or damaged copy is
rebuilt (with a logged warning naming what was wrong), never trusted.

Folder: ``$CAPNAV_ONNX_CACHE``, else ``~/.cache/capnav/onnx``; ``CAPNAV_ONNX_CACHE=off`` disables it.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path
from typing import Any

from capnav.core.atomic import atomic_path, write_json
from capnav.core.checksum import sha256_file

log = logging.getLogger(__name__)


def cache_dir() -> Path | None:
    env = os.environ.get("CAPNAV_ONNX_CACHE")
    if env is not None and env.strip().lower() in ("off", "0", "no", "false", ""):
        return None
    return Path(env).expanduser() if env else Path.home() / ".cache" / "capnav" / "onnx"


def _load_cached(ort: Any, path: Path, sidecar: Path, opts: Any) -> Any | None:
    import json

    if not path.is_file() or not sidecar.is_file():
        return None
    try:
        want = json.loads(sidecar.read_text())["sha256"]
        if sha256_file(path) != want:
            log.warning("optimised model copy %s does not match its recorded sha256; rebuilding it", path)
            return None
        opts.graph_optimization_level = ort.GraphOptimizationLevel.ORT_DISABLE_ALL
        return ort.InferenceSession(str(path), sess_options=opts, providers=["CPUExecutionProvider"])
    except Exception as e:  # unreadable sidecar, a file onnxruntime refuses: rebuild, do not fail the query
        log.warning("cannot use optimised model copy %s (%s); rebuilding it", path, e)
        return None


def session(model_path: Path, digest: str, make_options: Any) -> Any:
    """An ``InferenceSession`` for ``model_path`` (whose sha256 is ``digest``), from the optimised
    copy when one is cached, else building and caching it. ``make_options()`` returns fresh
    ``SessionOptions`` (threads etc.) for each attempt."""
    import onnxruntime as ort

    folder = cache_dir()
    if folder is None:
        return ort.InferenceSession(str(model_path), sess_options=make_options(), providers=["CPUExecutionProvider"])
    stem = f"{model_path.stem}-{digest[:16]}-ort{ort.__version__}"
    path, sidecar = folder / f"{stem}.onnx", folder / f"{stem}.json"
    cached = _load_cached(ort, path, sidecar, make_options())
    if cached is not None:
        return cached
    opts = make_options()
    opts.graph_optimization_level = ort.GraphOptimizationLevel.ORT_ENABLE_EXTENDED
    try:
        with atomic_path(path) as tmp:
            opts.optimized_model_filepath = str(tmp)
            sess = ort.InferenceSession(str(model_path), sess_options=opts, providers=["CPUExecutionProvider"])
            digest_copy = sha256_file(tmp)
        write_json(sidecar, {"source": str(model_path), "source_sha256": digest, "onnxruntime": ort.__version__,
                             "sha256": digest_copy})
        return sess
    except OSError as e:  # a read-only or full cache folder: run without the copy
        log.warning("cannot write the optimised model copy to %s (%s); optimising in memory", folder, e)
        return ort.InferenceSession(str(model_path), sess_options=make_options(), providers=["CPUExecutionProvider"])
