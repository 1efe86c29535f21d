"""The paper's exact prompts (section 3.3 caption prompt, section 3.4 verification prompt) and
strict parsers of the answers they ask for."""

from __future__ import annotations

import re
from dataclasses import dataclass

from capnav.core.errors import ModelError

#: Section 3.3, verbatim. The category hint is appended by ``caption_prompt``.
CAPTION_PROMPT = (
    "You will receive up to five full-frame indoor RGB images of the SAME tracked object. Each image "
    "highlights the object with a visible bounding box describe ONLY that object. The provided category "
    "hint may be incorrect. Infer the ACTUAL object category; start with the inferred name in UPPERCASE, "
    "followed by a comma, and then a single sentence (≤ 25 words) describing appearance, color, material, "
    "or notable condition. Do not mention uncertainty, other objects, or metadata."
)

#: Section 3.4, verbatim ("{object_type}" is filled in by ``verification_prompt``).
VERIFY_PROMPT = (
    "You are helping a mobile robot find a {object_type}. The objects in this batch are sorted by "
    "semantic relevance. For this batch only, your job is: (1) inspect each object's image and caption; "
    "(2) decide if any object IS actually a {object_type} (or a very close match); (3) if so, respond "
    "*exactly* with 'ACCEPT k: <short reason>' using 1-based indexing; (4) otherwise respond *exactly* "
    "with 'REJECT ALL: <short reason>'. Do not pick visually similar but incorrect objects, and do not "
    "refer to or compare against any objects outside this batch."
)

MAX_CAPTION_WORDS = 25


def caption_prompt(category_hint: str | None) -> str:
    hint = category_hint.strip() if category_hint else "unknown"
    return f"{CAPTION_PROMPT}\nCategory hint: {hint}"


def verification_prompt(object_type: str, captions: list[str]) -> str:
    lines = [VERIFY_PROMPT.format(object_type=object_type), ""]
    lines += [f"Object {k}: {c}" for k, c in enumerate(captions, start=1)]
    return "\n".join(lines)


_CAPTION_RE = re.compile(r"^\s*([A-Z][A-Z0-9 '\-/&]*[A-Z0-9])\s*,\s*(.+?)\s*$", re.S)


def parse_caption(text: str) -> str:
    """Validate a caption against the schema "NAME, one sentence (<= 25 words)" and return it
    normalised; raise ``ModelError`` saying what is off-schema."""
    if not isinstance(text, str) or not text.strip():
        raise ModelError("empty caption")
    t = " ".join(text.strip().strip('"').split())
    m = _CAPTION_RE.match(t)
    if m is None:
        raise ModelError(f"caption does not start with an UPPERCASE name and a comma: {t[:80]!r}")
    name, sentence = m.group(1), m.group(2)
    words = sentence.split()
    if len(words) > MAX_CAPTION_WORDS:
        raise ModelError(f"caption sentence has {len(words)} words (max {MAX_CAPTION_WORDS})")
    body = sentence.rstrip(".")
    if re.search(r"[.!?]\s+\S", body):
        raise ModelError("caption has more than one sentence")
    return f"{name}, {sentence}"


def caption_name(caption: str) -> str:
    """The object name of a schema caption, lower case ("WHITE SOFA, ..." -> "white sofa")."""
    return caption.split(",", 1)[0].strip().lower()


@dataclass(frozen=True)
class Verdict:
    """A parsed verification answer: ``index`` is 0-based, or None for REJECT ALL."""

    index: int | None
    reason: str


_ACCEPT_RE = re.compile(r"^\s*ACCEPT\s+(\d+)\s*:\s*(.*?)\s*$", re.S)
_REJECT_RE = re.compile(r"^\s*REJECT ALL\s*:\s*(.*?)\s*$", re.S)


def parse_verdict(text: str, batch_size: int) -> Verdict:
    """Strictly parse 'ACCEPT k: reason' (1-based k within the batch) or 'REJECT ALL: reason'."""
    t = (text or "").strip().strip("`").strip()
    m = _ACCEPT_RE.match(t)
    if m:
        k = int(m.group(1))
        if not 1 <= k <= batch_size:
            raise ModelError(f"verifier accepted object {k} of a batch of {batch_size}")
        return Verdict(k - 1, m.group(2).strip("<> ") or "accepted")
    m = _REJECT_RE.match(t)
    if m:
        return Verdict(None, m.group(1).strip("<> ") or "rejected")
    raise ModelError(f"verifier answer is neither 'ACCEPT k: ...' nor 'REJECT ALL: ...': {t[:80]!r}")
