"""CapNav: description-first indoor navigation.

Stages (one sub-package each): ``sim`` -> ``io`` -> ``perception`` -> ``mapping`` -> ``language``
-> ``retrieval`` -> ``planning``, with ``eval`` and ``viz`` on the side. ``core`` holds the
conventions every stage shares (frames, poses, grids, errors, registries).
"""

__version__ = "0.1.0"
