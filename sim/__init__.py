"""The simulator: a building, a robot that senses it, maps it, decides and drives, and the experiments around it.

Packages, in the order data flows through a trial; each may import only the
core (``abstract_map``) and the packages before it (``tests/sim/test_layout.py``
enforces this):

- ``sim.world``: world folders as data, the pybullet scene and robot, the
  reading rule, the oracle (everything true of the building itself);
- ``sim.perception``: what the robot senses: tags (camera or geometric) and
  the laser;
- ``sim.mapping``: what it remembers of the space: the occupancy grid;
- ``sim.navigation``: what it decides: the navigator (the abstract map's side),
  targets, plans, re-plans and the path follower;
- ``sim.experiments``: trials, studies, reports, pictures and their commands.
"""
