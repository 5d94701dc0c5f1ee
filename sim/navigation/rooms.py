"""Rooms behind doors labelled with another area's place: where the goal's label is unlikely to hang.

A room's label hangs beside its door on the side the door is approached from
(``worlds/README.md``), and a room reached through a room belongs to its host's
area (a suite: a department's rooms open off one another, not off another
department's). So once the label beside a door has been read and names a place
of an area that does not hold the goal, the room behind that door, and any
room reached through it, holds no label of the goal's, unless the building
mixes areas within a suite (``RoomParams.other_suite_prob``).

The room is found on the robot's own map (world frame, metres): the doorway is
a gap in the label's wall, ``door_min_m`` to ``door_width_m`` wide, within
``door_near_m`` of the label; the room is the open space behind the label's
wall, joined to a point just behind it without passing through anything as
narrow as that doorway, within ``reach_m`` of the label. So a mapped room's
region is the room itself (the rooms reached through it lie behind doorways
of their own). Unseen space counts as open, so before the room is mapped its
region is the unseen space behind the wall out to ``reach_m``: on the
generator's buildings a block of rooms between corridors is one area, so that
is still the label's area. A label with no doorway beside it (an enclosure's
plate in a zoo, a sign on open ground) says nothing here.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from sim.mapping.occupancy import OccupancyGrid
from sim.navigation.planner import clearance_m


@dataclass(frozen=True)
class RoomParams:
    """Which doors a label stands beside, and what the room behind says of the goal."""

    other_suite_prob: float = 0.1  # chance a room behind a door labelled with another area's place still holds the
    # goal's label (a suite mixing areas, a label misread): the generator never mixes them, real buildings seldom
    # do; as sure as an arrow naming the goal (``RouteParams.wrong_prob``)
    door_width_m: float = 1.3  # m; narrower passages are doorways (``RouteParams.door_width_m``)
    door_near_m: float = 1.5  # m from the label within which its doorway lies: the generator hangs a label
    # 0.85 m from its door's centre (``sim.world.layout.LABEL_OFFSET_M``), a door is 1 m wide
    door_min_m: float = 0.6  # m, the narrowest gap counted as a doorway (a mapped wall's specks leave less)
    wall_line_m: float = 0.12  # m behind the label to its wall's mid-line: the label hangs on the face (0.02 m in
    # front of it) of a 0.2 m wall (``sim.world.layout``)
    behind_m: float = 1.0  # m behind the label where the room's space is looked for (past a 0.2 m wall)
    reach_m: float = 8.0  # m from the label the room may reach: a generated room's far wall (blocks are 10-20 m
    # between corridors, two rooms deep) and little of the next block


def doorway_beside(grid: OccupancyGrid, free: np.ndarray, label_xy: np.ndarray, facing: float,
                   params: RoomParams) -> bool:
    """Whether the wall a label at ``label_xy`` (m) facing ``facing`` (rad) hangs on has a doorway beside it: a
    run of mapped free cells (``free``, the grid's :meth:`~sim.mapping.occupancy.OccupancyGrid.free_mask`) along
    the wall's mid-line, ``wall_line_m`` behind the label, at least ``door_min_m`` and at most ``door_width_m``
    long, reaching within ``door_near_m`` of the label."""
    along = np.arange(-params.door_near_m - params.door_width_m, params.door_near_m + params.door_width_m + 1e-9,
                      grid.resolution / 2)
    normal = np.array([math.cos(facing), math.sin(facing)])
    points = label_xy - params.wall_line_m * normal + along[:, None] * np.array([-normal[1], normal[0]])
    cells = grid.world_to_cell(points)
    rows, cols = grid.shape
    on = (cells[:, 0] >= 0) & (cells[:, 0] < rows) & (cells[:, 1] >= 0) & (cells[:, 1] < cols)
    gap = np.zeros(len(along), dtype=bool)
    gap[on] = free[cells[on, 0], cells[on, 1]]
    parts, count = ndimage.label(gap)
    for k in range(1, count + 1):
        run = along[parts == k]
        length = run[-1] - run[0] + grid.resolution
        if params.door_min_m <= length <= params.door_width_m and np.min(np.abs(run)) <= params.door_near_m:
            return True
    return False


def behind_door(grid: OccupancyGrid, label_xy: tuple[float, float], facing: float, clearance: np.ndarray,
                free: np.ndarray, params: RoomParams = RoomParams()) -> np.ndarray | None:
    """Bool per grid cell: the room behind the door beside the label at ``label_xy`` (m) facing ``facing``
    (rad), or None when no doorway is mapped beside it (:func:`doorway_beside`). ``clearance``: per cell, the
    distance (m) to the nearest mapped wall, exact up to half ``door_width_m``
    (:func:`sim.navigation.planner.clearance_m`); ``free``: the grid's mapped free cells."""
    label = np.asarray(label_xy, dtype=float)
    if not doorway_beside(grid, free, label, facing, params):
        return None
    res, (rows, cols) = grid.resolution, grid.shape
    reach = int(math.ceil(params.reach_m / res)) + 1
    centre = grid.world_to_cell(label)[0]
    r0, c0 = max(0, int(centre[0]) - reach), max(0, int(centre[1]) - reach)
    r1, c1 = min(rows, int(centre[0]) + reach + 1), min(cols, int(centre[1]) + reach + 1)
    if r0 >= r1 or c0 >= c1:
        return None
    rr, cc = np.mgrid[r0:r1, c0:c1]
    xy = grid.cell_to_world(np.stack([rr.ravel(), cc.ravel()], axis=1)).reshape(r1 - r0, c1 - c0, 2)
    d = xy - label
    ahead = d[..., 0] * math.cos(facing) + d[..., 1] * math.sin(facing)
    inside = (ahead < -params.wall_line_m) & (np.hypot(d[..., 0], d[..., 1]) <= params.reach_m)
    core = inside & (clearance[r0:r1, c0:c1] >= params.door_width_m / 2)  # open space no doorway lets through
    parts, _ = ndimage.label(core, structure=np.ones((3, 3)))
    seed = label - params.behind_m * np.array([math.cos(facing), math.sin(facing)])
    near = (parts > 0) & (np.hypot(xy[..., 0] - seed[0], xy[..., 1] - seed[1]) <= params.door_near_m)
    if not np.any(near):
        return None
    room = np.isin(parts, np.unique(parts[near]))
    # The space along the room's walls, nearer a wall than any core cell, is the room's too.
    grown = ndimage.binary_dilation(room, iterations=int(math.ceil(params.door_width_m / 2 / res)) + 1)
    out = np.zeros(grid.shape, dtype=bool)
    out[r0:r1, c0:c1] = grown & inside
    return out


def other_rooms_likelihood(grid: OccupancyGrid, labels: Iterable[tuple[tuple[float, float], float]],
                           params: RoomParams = RoomParams()) -> np.ndarray | None:
    """Per cell of ``grid``, the likelihood of the goal's label there given that the labels at ``labels``
    (position m, facing rad) name places of areas that do not hold the goal: ``other_suite_prob`` in the
    rooms behind their doors (:func:`behind_door`), 1 elsewhere; None when no such label has a doorway
    mapped beside it."""
    labels = list(labels)
    if not labels:
        return None
    clearance, free = clearance_m(grid, params.door_width_m / 2), grid.free_mask()
    out = np.ones(grid.shape)
    found = False
    for xy, facing in labels:
        room = behind_door(grid, xy, facing, clearance, free, params)
        if room is not None:
            out[room] = params.other_suite_prob
            found = True
    return out if found else None
