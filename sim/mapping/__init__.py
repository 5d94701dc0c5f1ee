"""Mapping: what the robot remembers of the space it has sensed.

The log-odds occupancy grid built from laser scans (``occupancy``). May import
``sim.world`` and ``sim.perception``.
"""
