"""Conventions shared by every stage: frames, poses, grids, categories, errors, registries."""
