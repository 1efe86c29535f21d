"""Baselines re-implemented in the harness: VLMaps-style, category-only, random-object.

The exploration baselines (CoW-, ZSON-, LM-Nav-style) live in ``explore/``.
"""
