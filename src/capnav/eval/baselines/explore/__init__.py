"""Exploration baselines of the paper's Table 1 on one frontier-exploration core.

``cow`` (CLIP on Wheels-style), ``zson`` (ZSON-style) and ``lmnav`` (LM-Nav-style) register in
``capnav.eval.method.METHODS`` when this package is imported. None uses the prior map: CoW and
ZSON build their own occupancy online from the agent's depth; LM-Nav builds a topological graph
from the shared exploration stream.
"""

from capnav.eval.baselines.explore import cow as _cow  # noqa: F401  (registers "cow")
from capnav.eval.baselines.explore import lmnav as _lmnav  # noqa: F401  (registers "lmnav")
from capnav.eval.baselines.explore import zson as _zson  # noqa: F401  (registers "zson")
