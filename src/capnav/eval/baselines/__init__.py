"""Baselines re-implemented in the harness (VLMaps-style, category-only, random-object; exploration baselines in ``explore/``)."""
