"""Navigation: what the robot decides from what it sensed and remembers.

The navigator (``navigator``: tag sightings into the abstract map, the goal's
imagined position out), where to drive (``targeting``), shortest paths over
the occupancy grid (``planner``), when to plan again (``replanner``) and
driving along a path (``follower``); frontiers (``frontier``), swept space and
the goal belief (``belief``), readable viewpoints (``viewpoints``), what arrows
and doorways say of where the goal is (``routes``), and the navigation
policies by name (``policies``). May import the core, ``sim.world``,
``sim.perception`` and ``sim.mapping``.
"""
