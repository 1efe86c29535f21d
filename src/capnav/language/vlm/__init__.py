"""Vision-language model clients shared by the captioners and the verifiers: a prompt and PNG
images in, raw text out. Errors are ``ModelError``; rate limits are ``RateLimited``."""

from capnav.language.vlm.base import VLMS, RateLimited, VisionLanguageModel, create_vlm

__all__ = ["VLMS", "RateLimited", "VisionLanguageModel", "create_vlm"]
