"""The world: everything true of a building, independent of any robot's knowledge.

World folders as data (``data``), the pybullet scene built from them
(``scene``, with pure wall geometry in ``walls`` and tag images in
``tag_texture``), the GuiaBot (``robot``, ``urdf/``), the rule for when a tag
can be read (``visibility``), pose checks (``pose``) and the oracle's shortest
paths (``oracle``). Imports only the core; nothing later in the flow.
"""
