"""A local vision-language model through HF transformers, from a local folder only.

Any model that ``AutoModelForImageTextToText`` and ``AutoProcessor`` load (LLaVA, Qwen2-VL,
SmolVLM, ...) and whose processor has a chat template. Greedy decoding, so answers are
reproducible; ``local_files_only=True`` so nothing is downloaded.
"""

from __future__ import annotations

import io
import os
from pathlib import Path
from typing import Any

from capnav.core.errors import ModelError, pip_hint
from capnav.language.vlm.base import VLMS


class HFLocalVLM:
    def __init__(self, path: str | os.PathLike[str], max_new_tokens: int = 64, device: str = "cpu",
                 max_image_side: int = 448) -> None:
        p = Path(path)
        if not p.is_dir():
            raise ModelError(f"local VLM folder not found: {p}")
        try:
            from transformers import AutoModelForImageTextToText, AutoProcessor
        except ImportError:
            raise ModelError(f"transformers is not installed: {pip_hint('capnav[vlm]')}") from None
        try:
            self._proc = AutoProcessor.from_pretrained(str(p), local_files_only=True)
            model: Any = AutoModelForImageTextToText.from_pretrained(str(p), local_files_only=True)
            self._model = model.to(device)
        except Exception as e:
            raise ModelError(f"cannot load a vision-language model from {p}: {e}") from None
        self._model.eval()
        self._device = device
        self.max_new_tokens = int(max_new_tokens)
        self.max_image_side = int(max_image_side)
        self.model_id = f"hf-local:{p.name}"

    def ask(self, prompt: str, images: list[bytes]) -> str:
        import torch
        from PIL import Image

        pics = []
        for png in images:
            im = Image.open(io.BytesIO(png)).convert("RGB")
            im.thumbnail((self.max_image_side, self.max_image_side))
            pics.append(im)
        content: list[dict[str, Any]] = [{"type": "image"} for _ in pics]
        content.append({"type": "text", "text": prompt})
        try:
            text = self._proc.apply_chat_template([{"role": "user", "content": content}], add_generation_prompt=True)
            inputs = self._proc(text=text, images=pics or None, return_tensors="pt").to(self._device)
            with torch.inference_mode():
                out = self._model.generate(**inputs, max_new_tokens=self.max_new_tokens, do_sample=False)
        except Exception as e:
            raise ModelError(f"{self.model_id} failed to generate: {type(e).__name__}: {e}") from None
        new = out[:, inputs["input_ids"].shape[1]:]
        return str(self._proc.batch_decode(new, skip_special_tokens=True)[0]).strip()


@VLMS.register("hf-local")
def hf_local(path: str | os.PathLike[str], **kwargs: Any) -> HFLocalVLM:
    return HFLocalVLM(path, **kwargs)
