"""The verification step ("AGENT", paper 3.4): candidates in batches, in order of relevance; a
verifier answers "ACCEPT k: reason" or "REJECT ALL: reason" per batch.

Backends: ``vlm`` clients (Gemini, OpenAI-compatible, local HF) with the paper's exact prompt and
strict parsing (off-schema answers are retried, then the offline verifier decides and the reason
says so); ``offline`` with the same interface, judging agreement between the instruction's target
and each caption's object name (same category, or embedding similarity of the names) plus
attribute agreement (colour by CIEDE2000 against the object's measured colour, size words
against its size among its category, shape words against its caption); ``none`` accepts the
first candidate. Decisions are cached (in the map's ``caches["verifications"]`` when given).
"""

from __future__ import annotations

import hashlib
import logging
import re
import time
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from capnav.core.errors import CapNavError
from capnav.core.registry import Registry
from capnav.language.captioner import RetryPolicy
from capnav.language.colors import ColorCluster, color_agreement
from capnav.language.context import SceneContext, canonical_label
from capnav.language.embedder import TextEmbedder
from capnav.language.offline_captioner import ObservationCaptioner
from capnav.language.prompts import Verdict, caption_name, parse_verdict, verification_prompt
from capnav.language.vlm.base import RateLimited, VisionLanguageModel, create_vlm
from capnav.mapping.objects import MapObject
from capnav.retrieval.query import ParsedQuery

log = logging.getLogger(__name__)


def a(noun: str) -> str:
    """'a chair', 'an armchair'."""
    return f"an {noun}" if noun[:1].lower() in "aeiou" else f"a {noun}"


@dataclass
class Candidate:
    obj: MapObject
    score: float  # cosine similarity (eq. 16)
    rank: int  # position in the retrieval order


def target_description(q: ParsedQuery) -> str:
    """The {object_type} of the verification prompt: the target with its predicates, in words."""
    parts = [q.target_phrase]
    if q.superlative:
        parts.insert(0, q.superlative)
    if q.relation and q.anchor_category:
        parts.append(f"{q.relation} a {q.anchor_category}")
    if q.room:
        parts.append(f"in the {q.room}")
    return " ".join(p for p in parts if p)


class Verifier(ABC):
    name: str

    @abstractmethod
    def verify(self, query: ParsedQuery, batch: list[Candidate]) -> Verdict: ...


VERIFIERS: Registry[Verifier] = Registry("verifier")


def create_verifier(name: str = "offline", **kwargs: Any) -> Verifier:
    """``offline`` (default), ``none``, or a VLM: ``gemini``, ``openai``, ``hf-local``."""
    return VERIFIERS.create(name, **kwargs)


class AcceptFirst(Verifier):
    """No verification: the first candidate of the first batch (ablation "w/o AGENT")."""

    name = "none"

    def verify(self, query: ParsedQuery, batch: list[Candidate]) -> Verdict:
        if not batch:
            return Verdict(None, "empty batch")
        return Verdict(0, "accepted without verification (highest retrieval rank)")


@dataclass(frozen=True)
class OfflineVerifierConfig:
    name_threshold: float = 0.78  # cosine between target noun and caption name for a non-category match
    color_reject: float = 0.05  # exp(-ΔE/12) below this (ΔE00 > 36) the colour clearly disagrees
    w_rank: float = 0.5
    w_color: float = 1.0
    w_size: float = 0.6
    w_shape: float = 0.3


class OfflineVerifier(Verifier):
    name = "offline"

    def __init__(self, embedder: TextEmbedder | None = None, scene: SceneContext | None = None,
                 config: OfflineVerifierConfig | None = None) -> None:
        self.embedder = embedder
        self.scene = scene
        self.config = config or OfflineVerifierConfig()
        self._colors: dict[int, list[ColorCluster]] = {}
        self._base_colors: dict[int, list[ColorCluster]] = {}
        self._captioner = ObservationCaptioner()

    def bind(self, embedder: TextEmbedder, scene: SceneContext) -> None:
        self.embedder = self.embedder or embedder
        self.scene = scene

    def use_attributes(self, attributes: dict[str, Any]) -> None:
        """Colours measured by ``describe_map`` (``cmap.caches["attributes"]``), so queries need not
        recompute them."""
        for key, rec in attributes.items():
            for field_, store in (("colors", self._colors), ("base_colors", self._base_colors)):
                if field_ in rec:
                    store[int(key)] = [ColorCluster(str(n), (float(L), float(a), float(b)), float(f), float(d))
                                       for n, L, a, b, f, d in rec[field_]]

    def colors(self, obj: MapObject) -> list[ColorCluster]:
        if obj.id not in self._colors:
            self._colors[obj.id] = self._captioner.colors(obj)
        return self._colors[obj.id]

    def base_colors(self, obj: MapObject) -> list[ColorCluster]:
        if obj.id not in self._base_colors:
            self._base_colors[obj.id] = self._captioner.base_colors(obj)
        return self._base_colors[obj.id]

    def _name_agreement(self, q: ParsedQuery, obj: MapObject) -> tuple[bool, str]:
        name = caption_name(obj.caption or obj.label)
        cat = canonical_label(name)
        if q.category is not None and (cat == q.category or canonical_label(obj.label) == q.category):
            return True, f"it is {a(q.category)}"
        noun = q.category or (" ".join(q.unknown_words) if q.unknown_words else q.target_phrase)
        if self.embedder is None or not noun:
            return False, f"it is {a(name)}, not {a(noun)}"
        v = self.embedder.embed([noun, name])
        sim = float(v[0] @ v[1])
        if sim >= self.config.name_threshold:
            return True, f"'{name}' matches '{noun}' (similarity {sim:.2f})"
        return False, f"it is {a(name)}, not {a(noun)} (similarity {sim:.2f})"

    def _color(self, q: ParsedQuery, obj: MapObject) -> tuple[float, str]:
        if not q.colors:
            return 0.0, ""
        # "the plant in the blue pot": the colour of the object's base, not of its leaves.
        cols = self.base_colors(obj) if re.search(r"\bpot\b", q.text.lower()) else []
        cols = cols or self.colors(obj)
        if not cols:
            return 0.0, "its colour was not observed"
        vals = []
        for word in q.colors:
            vals.append(max(color_agreement(word, c.lab) * (0.6 + 0.4 * min(1.0, c.fraction / 0.5)) for c in cols))
        agree = float(np.mean(vals))
        return agree, f"colour {'/'.join(q.colors)} vs observed {cols[0].name} (agreement {agree:.2f})"

    def _size(self, q: ParsedQuery, obj: MapObject) -> float:
        if q.size_word is None or self.scene is None or obj.id not in self.scene.index:
            return 0.0
        rank, count = self.scene.size_rank(obj)
        if count < 2:
            return 0.5
        frac = rank / (count - 1)  # 0 = largest
        return 1.0 - frac if q.size_word == "large" else frac

    def verify(self, query: ParsedQuery, batch: list[Candidate]) -> Verdict:
        cfg = self.config
        best: tuple[float, int, str] | None = None
        rejects: list[str] = []
        for i, c in enumerate(batch):
            ok, why = self._name_agreement(query, c.obj)
            if not ok:
                rejects.append(why)
                continue
            col, cwhy = self._color(query, c.obj)
            if query.colors and col < cfg.color_reject:
                rejects.append(f"{why} but {cwhy}")
                continue
            shape = 0.0
            if query.shapes and c.obj.caption:
                shape = float(np.mean([s.lower() in c.obj.caption.lower() for s in query.shapes]))
            val = (cfg.w_rank * (1.0 - i / max(len(batch), 1)) + cfg.w_color * col
                   + cfg.w_size * self._size(query, c.obj) + cfg.w_shape * shape)
            reason = "; ".join(x for x in (why, cwhy) if x)
            if best is None or val > best[0]:
                best = (val, i, reason)
        if best is None:
            return Verdict(None, rejects[0] if rejects else "no candidate")
        return Verdict(best[1], best[2])


class VLMVerifier(Verifier):
    """The paper's verification prompt over each candidate's best crop and caption."""

    def __init__(self, client: VisionLanguageModel, retry: RetryPolicy | None = None,
                 fallback: Verifier | None = None, cache: dict[str, Any] | None = None,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        self.client = client
        self.name = client.model_id
        self.retry = retry or RetryPolicy()
        self.fallback = fallback or OfflineVerifier()
        self.cache: dict[str, Any] = {} if cache is None else cache
        self._sleep = sleep

    def _images(self, batch: list[Candidate]) -> list[bytes]:
        out = []
        for c in batch:
            v = c.obj.views[0] if c.obj.views else None
            if v is not None and (v.crop_png or v.frame_png):
                out.append(v.crop_png or v.frame_png)
        return out

    def verify(self, query: ParsedQuery, batch: list[Candidate]) -> Verdict:
        prompt = verification_prompt(target_description(query), [c.obj.caption or c.obj.label for c in batch])
        images = self._images(batch)
        h = hashlib.sha256((self.name + "\0" + prompt).encode())
        for img in images:
            h.update(hashlib.sha256(img).digest())
        key = h.hexdigest()
        if key in self.cache:
            d = self.cache[key]
            return Verdict(d["index"], d["reason"])
        reason = "no attempt"
        for attempt in range(self.retry.attempts):
            try:
                verdict = parse_verdict(self.client.ask(prompt, images), len(batch))
                self.cache[key] = {"index": verdict.index, "reason": verdict.reason, "model": self.name}
                return verdict
            except RateLimited as e:
                reason, wait = str(e), e.retry_after if e.retry_after is not None else self.retry.backoff * 2**attempt
            except CapNavError as e:
                reason, wait = str(e), self.retry.backoff * 2**attempt
            if attempt + 1 < self.retry.attempts:
                self._sleep(min(wait, self.retry.max_backoff))
        log.warning("%s verification failed (%s); using the offline verifier", self.name, reason)
        v = self.fallback.verify(query, batch)
        return Verdict(v.index, f"{v.reason} (offline fallback: {reason})")


@VERIFIERS.register("none")
def _none(**_: Any) -> AcceptFirst:
    return AcceptFirst()


@VERIFIERS.register("offline")
def _offline(embedder: TextEmbedder | None = None, **kw: Any) -> OfflineVerifier:
    return OfflineVerifier(embedder=embedder, config=OfflineVerifierConfig(**kw) if kw else None)


def _vlm_factory(backend: str) -> Callable[..., VLMVerifier]:
    def make(retry: RetryPolicy | None = None, fallback: Verifier | None = None, cache: dict[str, Any] | None = None,
             sleep: Callable[[float], None] = time.sleep, embedder: TextEmbedder | None = None,
             **client_kw: Any) -> VLMVerifier:
        fb = fallback if fallback is not None else OfflineVerifier(embedder=embedder)
        return VLMVerifier(create_vlm(backend, **client_kw), retry=retry, fallback=fb, cache=cache, sleep=sleep)

    return make


for _name in ("gemini", "openai", "hf-local"):
    VERIFIERS.register(_name)(_vlm_factory(_name))
