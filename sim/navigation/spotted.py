"""Tags seen but not yet read: where the goal's label can only be, once a wall has been seen from afar.

Labels are plates on walls, and the robot sees a plate long before it can
read it (:mod:`sim.perception.spotting`: 8 m, 75 degrees off its normal,
against reading's 4 m and 45). So a wall seen within that rule without a plate
on it holds no label, and a plate seen but unread may be the goal's label or a
sign that names it. :class:`SpottedTags` keeps the plates seen and not yet
read, and gives the guided search three grids (the occupancy grid's cells):

- ``tag_cells``: the cells of unread plates (the belief keeps them unswept,
  whatever the look says);
- ``read_cells``: the cells of plates read (not the goal's label: swept);
- ``zones``: for each unread plate, the free space in front of it from which it
  is read (square to it, 1.2-3 m out): the search treats that space as not yet
  looked at, so a frontier forms there and carries the plate's belief, and the
  robot drives to stand in front of it. A label hangs only on a plate, so a
  plate stands for the wall around it that a label could have hung on
  (``plate_wall_m``), and its zone is worth the belief along that much wall;
- ``door_stop``: where to read the first unread plate beside a doorway that a
  planned path is about to pass through into the space behind the plate. A
  door's plate hangs beside it facing the way the door is approached and names
  the room behind, so a person reads it before going in; a robot that turns
  in first has the plate edge-on and then behind it.

World frame, metres.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator
from dataclasses import dataclass

import numpy as np

from sim.mapping.occupancy import OccupancyGrid
from sim.navigation.belief import cell_window
from sim.perception.sighting import Sighting
from sim.perception.spotting import Spot


@dataclass(frozen=True)
class SpottedParams:
    """How plates seen but unread are kept and approached."""

    same_tag_m: float = 0.3  # m; reports of plates this close are one plate (spots and sightings are true poses)
    tag_radius_m: float = 0.25  # m; cells this close to a plate's centre are its cells (a plate is ~0.25 m wide)
    zone_near_m: float = 1.2  # m in front of a plate where its reading zone starts: the camera misses nearer tags
    zone_far_m: float = 3.0  # m where it ends: inside the 4 m reading range with the sweep's margin
    zone_half_angle_deg: float = 30.0  # deg about the plate's normal: inside the 45-degree reading cone, so the
    # zone's edge, where the robot arrives, still reads it
    sweep_range_m: float = 7.5  # m; a wall this close, seen in the spotting cone, would have shown its plate:
    # the spotter's 8 m less a margin
    sweep_cone_deg: float = 70.0  # deg about the wall's normal: the spotter's 75 less a margin
    sweep_every_s: float = 0.4  # s of simulated time between such sweeps: the perception's 2.5 Hz
    door_reach_m: float = 1.5  # m along its wall from a plate where a path crossing the wall passes the plate's
    # door: a door's width (about 1 m) plus the plate's offset from its jamb
    read_at_m: float = 2.0  # m out along a plate's normal where the robot stops to read it before its door:
    # the middle of the reading zone
    plate_wall_m: float = 26.0  # m of wall a plate seen stands for: a label hangs only on a plate, so a plate is
    # worth the belief along the wall a plate stands for, not only on its own half metre. Development buildings
    # 100-147 have 24.9-27.9 m of reachable wall face per plate (docs/method-notes.md, "A plate stands for the
    # wall around it"); valued so, plates are weighed by the arrows too (RouteParams.front_m)


class SpottedTags:
    """Plates seen and not yet read, and plates read, by where they hang."""

    def __init__(self, params: SpottedParams | None = None) -> None:
        self.params = params or SpottedParams()
        self.unread: list[Spot] = []
        self.read: list[tuple[float, float]] = []
        self.version = 0  # bumped whenever either list changes

    def update(self, sightings: Iterable[Sighting], spots: Iterable[Spot]) -> bool:
        """Take in the plates read and seen now; True when anything changed."""
        changed = False
        for s in sightings:
            if not self._near(self.read, s.x, s.y):
                self.read.append((s.x, s.y))
                changed = True
        keep = [u for u in self.unread if not self._near(self.read, u.x, u.y)]
        changed |= len(keep) != len(self.unread)
        self.unread = keep
        for spot in spots:
            if not self._near(self.read, spot.x, spot.y) and not self._near(
                    [(u.x, u.y) for u in self.unread], spot.x, spot.y):
                self.unread.append(spot)
                changed = True
        if changed:
            self.version += 1
        return changed

    def _near(self, points: list[tuple[float, float]], x: float, y: float) -> bool:
        return any(math.hypot(px - x, py - y) <= self.params.same_tag_m for px, py in points)

    def tag_cells(self, grid: OccupancyGrid) -> np.ndarray:
        """Bool, the grid's shape: cells within ``tag_radius_m`` of an unread plate."""
        return self._disc_cells(grid, [(u.x, u.y) for u in self.unread])

    def read_cells(self, grid: OccupancyGrid) -> np.ndarray:
        """Bool, the grid's shape: cells within ``tag_radius_m`` of a plate read."""
        return self._disc_cells(grid, self.read)

    def _disc_cells(self, grid: OccupancyGrid, points: list[tuple[float, float]]) -> np.ndarray:
        out = np.zeros(grid.shape, dtype=bool)
        axes = grid.cell_axes()
        for x, y in points:
            rows, cols, dx, dy = _around(grid, axes, x, y, self.params.tag_radius_m)
            out[rows, cols] |= np.hypot(dx, dy) <= self.params.tag_radius_m
        return out

    def _zone_blocks(self, grid: OccupancyGrid) -> Iterator[tuple[Spot, slice, slice, np.ndarray, np.ndarray]]:
        """For each unread plate: (plate, rows slice, cols slice, its zone on that window (bool), each window
        cell's distance from the plate (m))."""
        prm = self.params
        axes = grid.cell_axes()
        cos_min = math.cos(math.radians(prm.zone_half_angle_deg))
        for u in self.unread:
            rows, cols, dx, dy = _around(grid, axes, u.x, u.y, prm.zone_far_m)
            d = np.hypot(dx, dy)
            ahead = (dx * math.cos(u.theta) + dy * math.sin(u.theta)) >= d * cos_min
            yield u, rows, cols, ahead & (d >= prm.zone_near_m) & (d <= prm.zone_far_m), d

    def zones(self, grid: OccupancyGrid) -> np.ndarray:
        """Bool, the grid's shape: cells not on a mapped wall in front of an unread plate from which it is read
        (``zone_near_m`` to ``zone_far_m`` out, within ``zone_half_angle_deg`` of its normal)."""
        out = np.zeros(grid.shape, dtype=bool)
        for _, rows, cols, zone, _ in self._zone_blocks(grid):
            out[rows, cols] |= zone
        return out & ~grid.occupied_mask()

    def zone_values(self, grid: OccupancyGrid, mass: np.ndarray) -> np.ndarray:
        """Per cell, the belief ``mass`` (the grid's shape) on the plate whose reading zone holds it (the most,
        where zones overlap), times ``plate_wall_m`` over the plate's width: what standing there would read."""
        out = np.zeros(grid.shape)
        worth = max(1.0, self.params.plate_wall_m / (2.0 * self.params.tag_radius_m))
        for _, rows, cols, zone, d in self._zone_blocks(grid):
            on_plate = float(mass[rows, cols][d <= self.params.tag_radius_m].sum()) * worth
            out[rows, cols] = np.maximum(out[rows, cols], np.where(zone, on_plate, 0.0))
        return out

    def door_stop(self, waypoints: np.ndarray) -> tuple[Spot, np.ndarray] | None:
        """The first unread plate whose door the path ``waypoints`` ((N, 2) m, from the robot) passes through
        from the plate's face to behind it, within ``door_reach_m`` of the plate along its wall, and the point
        ``read_at_m`` in front of it where it is read; None when the path passes no such door."""
        prm = self.params
        pts = np.asarray(waypoints, dtype=float)
        if not self.unread or len(pts) < 2:
            return None
        a, b = pts[:-1], pts[1:]
        first: tuple[int, Spot] | None = None
        for u in self.unread:
            normal = np.array([math.cos(u.theta), math.sin(u.theta)])
            ahead = (pts - [u.x, u.y]) @ normal  # m in front of the plate's wall
            cross = np.flatnonzero((ahead[:-1] > 0.0) & (ahead[1:] <= 0.0))
            if cross.size == 0:
                continue
            share = ahead[cross] / (ahead[cross] - ahead[cross + 1])
            at = a[cross] + share[:, None] * (b[cross] - a[cross])
            along = np.abs((at - [u.x, u.y]) @ np.array([-normal[1], normal[0]]))
            hits = cross[along <= prm.door_reach_m]
            if hits.size and (first is None or hits[0] < first[0]):
                first = (int(hits[0]), u)
        if first is None:
            return None
        u = first[1]
        return u, np.array([u.x + prm.read_at_m * math.cos(u.theta), u.y + prm.read_at_m * math.sin(u.theta)])

    def give_up_at(self, grid: OccupancyGrid, xy: np.ndarray) -> bool:
        """The robot stood at ``xy`` (m) and read no plate whose zone holds it: those plates cannot be read from
        where the robot gets to (hidden, or out of reach) and count as read. True when any did."""
        rc = grid.world_to_cell(np.asarray(xy, dtype=float))[0]
        dropped = []
        for u, rows, cols, zone, _ in self._zone_blocks(grid):
            r, c = int(rc[0]) - rows.start, int(rc[1]) - cols.start
            if 0 <= r < zone.shape[0] and 0 <= c < zone.shape[1] and zone[r, c]:
                dropped.append(u)
        if not dropped:
            return False
        self.unread = [u for u in self.unread if u not in dropped]
        self.read += [(u.x, u.y) for u in dropped]
        self.version += 1
        return True


def _around(grid: OccupancyGrid, axes: tuple[np.ndarray, np.ndarray], x: float, y: float, reach_m: float
            ) -> tuple[slice, slice, np.ndarray, np.ndarray]:
    """The window of ``grid`` holding every cell within ``reach_m`` of (``x``, ``y``) (m): its rows and columns
    (empty off the grid), and each column's and row's offset from the point (m; (1, cols) and (rows, 1)), from
    ``axes``, the grid's :meth:`~sim.mapping.occupancy.OccupancyGrid.cell_axes`."""
    rc = grid.world_to_cell(np.array([x, y], dtype=float))[0]
    r0, r1, c0, c1 = cell_window(rc, int(math.ceil(reach_m / grid.resolution)) + 1, grid.shape)
    rows, cols = slice(r0, max(r0, r1)), slice(c0, max(c0, c1))
    return rows, cols, axes[0][cols][None, :] - x, axes[1][rows][:, None] - y
