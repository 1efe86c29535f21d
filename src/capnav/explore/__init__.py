"""Exploring unseen space: an online occupancy map, frontiers, a frontier explorer, sightings,
and the object search of ``capnav navigate --search`` built on them.

The product part: ``capnav navigate --search`` searches with it when the map is silent or stale,
and the exploring baselines of the benchmark (``capnav.eval.baselines.explore``) run on the same core.
"""
