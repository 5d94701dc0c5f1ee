"""A log-odds occupancy grid built from 2D laser scans.

Frames: world frame, metres, radians counter-clockwise from +x. Cells are
indexed (row, col) with row 0 at the top (largest y), like
:class:`sim.world.data.Floorplan`, so images draw with ``imshow(...,
extent=grid.extent)`` and :func:`sim.perception.laser.grid_caster` can cast over
``occupied_mask()`` with ``grid.resolution`` and ``grid.origin``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from sim.world.data import Floorplan
from sim.world.pose import check_pose

FREE_GREY = 254  # map_server colours for to_image()
OCCUPIED_GREY = 0
UNKNOWN_GREY = 205


@dataclass(frozen=True)
class OccupancyParams:
    """Grid geometry and log-odds update model."""

    resolution_m: float = 0.1  # m, cell edge
    bounds: tuple[float, float, float, float] = (-29.5, 29.5, -18.1, 18.1)  # m, (x_min, x_max, y_min, y_max)
    l_occ: float = 0.85  # log-odds added to a cell a beam ends in
    l_free: float = -0.4  # log-odds added to a cell a beam passes through
    clamp: tuple[float, float] = (-2.0, 3.5)  # log-odds limits, keep the map responsive
    occupied_threshold: float = 0.4  # log-odds above which a cell is occupied
    free_threshold: float = -0.2  # log-odds below which a cell is free

    def __post_init__(self) -> None:
        if not (math.isfinite(self.resolution_m) and self.resolution_m > 0):
            raise ValueError(f"OccupancyParams.resolution_m must be finite and > 0, got {self.resolution_m}")
        x_min, x_max, y_min, y_max = self.bounds
        if not all(math.isfinite(v) for v in self.bounds) or x_max <= x_min or y_max <= y_min:
            raise ValueError(f"OccupancyParams.bounds must be finite (x_min < x_max, y_min < y_max), got {self.bounds}")
        if not (self.l_occ > 0 > self.l_free):
            raise ValueError(f"OccupancyParams: need l_occ > 0 > l_free, got {self.l_occ}, {self.l_free}")
        if not (self.clamp[0] < self.free_threshold < 0 < self.occupied_threshold < self.clamp[1]):
            raise ValueError("OccupancyParams: need clamp[0] < free_threshold < 0 < occupied_threshold < clamp[1], "
                             f"got clamp={self.clamp}, thresholds=({self.free_threshold}, {self.occupied_threshold})")


class OccupancyGrid:
    """Log-odds occupancy over ``params.bounds``; every cell starts unknown (log-odds 0)."""

    def __init__(self, params: OccupancyParams = OccupancyParams()) -> None:
        self.params = params
        x_min, x_max, y_min, y_max = params.bounds
        res = params.resolution_m
        cols = int(math.ceil((x_max - x_min) / res - 1e-9))
        rows = int(math.ceil((y_max - y_min) / res - 1e-9))
        self.log_odds = np.zeros((rows, cols), dtype=np.float32)
        self.version = 0  # counts changes (scans integrated); code editing log_odds directly bumps it too

    @property
    def resolution(self) -> float:
        """Cell edge (m)."""
        return self.params.resolution_m

    @property
    def origin(self) -> tuple[float, float]:
        """World position (m) of the bottom-left corner of cell (rows - 1, 0)."""
        return self.params.bounds[0], self.params.bounds[2]

    @property
    def shape(self) -> tuple[int, int]:
        """(rows, cols)."""
        return self.log_odds.shape  # type: ignore[return-value]

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max) in metres covered by the cells, for imshow."""
        rows, cols = self.shape
        x0, y0 = self.origin
        return (x0, x0 + cols * self.resolution, y0, y0 + rows * self.resolution)

    def world_to_cell(self, xy: np.ndarray) -> np.ndarray:
        """World points (N, 2) in m to integer (row, col) indices (N, 2); may lie outside the grid."""
        xy = np.atleast_2d(np.asarray(xy, dtype=float))
        x0, y0 = self.origin
        col = np.floor((xy[:, 0] - x0) / self.resolution).astype(int)
        row = self.shape[0] - 1 - np.floor((xy[:, 1] - y0) / self.resolution).astype(int)
        return np.stack([row, col], axis=1)

    def cell_to_world(self, rc: np.ndarray) -> np.ndarray:
        """Cell (row, col) indices (N, 2) to the world positions (m) of their centres (N, 2)."""
        rc = np.atleast_2d(np.asarray(rc, dtype=float))
        x0, y0 = self.origin
        x = x0 + (rc[:, 1] + 0.5) * self.resolution
        y = y0 + (self.shape[0] - 1 - rc[:, 0] + 0.5) * self.resolution
        return np.stack([x, y], axis=1)

    def cell_axes(self) -> tuple[np.ndarray, np.ndarray]:
        """World x (m) of each column's cell centres (cols,) and world y (m) of each row's (rows,)."""
        rows, cols = self.shape
        x = self.cell_to_world(np.stack([np.zeros(cols), np.arange(cols)], axis=1))[:, 0]
        y = self.cell_to_world(np.stack([np.arange(rows), np.zeros(rows)], axis=1))[:, 1]
        return x, y

    def in_bounds(self, rc: np.ndarray) -> np.ndarray:
        """Which (row, col) indices (N, 2) lie inside the grid, shape (N,)."""
        rc = np.atleast_2d(np.asarray(rc))
        rows, cols = self.shape
        return (rc[:, 0] >= 0) & (rc[:, 0] < rows) & (rc[:, 1] >= 0) & (rc[:, 1] < cols)

    def integrate(
        self,
        pose: tuple[float, float, float] | np.ndarray,
        angles: np.ndarray,
        ranges: np.ndarray,
        max_range: float,
        min_range: float = 0.0,
    ) -> None:
        """Update the grid with one scan taken at ``pose`` (x m, y m, theta rad).

        ``angles`` (rad, robot frame) and ``ranges`` (m) have one entry per beam.
        A beam with range < ``max_range`` hit something: the cell it ends in is
        marked occupied. Every beam marks the cells it crossed before its end
        free (no-hit beams up to ``max_range``). Each cell gets at most one
        update per scan, and a cell both crossed and hit counts as hit.
        Beams shorter than ``min_range`` (m; e.g. returns off the robot
        itself) are ignored.
        """
        x, y, theta = check_pose(pose)
        angles = np.asarray(angles, dtype=float).ravel()
        ranges = np.asarray(ranges, dtype=float).ravel()
        if angles.shape != ranges.shape:
            raise ValueError(f"integrate: angles {angles.shape} and ranges {ranges.shape} differ in shape")
        if not np.all(np.isfinite(angles)):
            raise ValueError("integrate: angles must be finite")
        if np.any(np.isnan(ranges)) or np.any(ranges < 0):
            raise ValueError("integrate: ranges must be >= 0 and not NaN (use inf or max_range for no hit)")
        if not (math.isfinite(max_range) and max_range > 0):
            raise ValueError(f"integrate: max_range must be finite and > 0, got {max_range}")
        if not (math.isfinite(min_range) and 0 <= min_range < max_range):
            raise ValueError(f"integrate: min_range must be in [0, max_range), got {min_range}")
        keep = ranges >= min_range
        angles, ranges = angles[keep], ranges[keep]
        if ranges.size == 0:
            return
        hit = ranges < max_range - 1e-6
        reach = np.minimum(ranges, max_range)
        world = theta + angles
        direction = np.stack([np.cos(world), np.sin(world)], axis=1)

        step = 0.5 * self.resolution
        d = step * np.arange(int(math.ceil(max_range / step)) + 1)
        # Free samples: strictly before the end of hit beams, up to and including the end of no-hit beams.
        before_end = np.where(hit[:, None], d[None, :] < reach[:, None], d[None, :] <= reach[:, None])
        px = x + direction[:, 0:1] * d[None, :]
        py = y + direction[:, 1:2] * d[None, :]
        free_r, free_c = self._cells_where(px, py, before_end)
        # Nudge hit points slightly along the beam so a hit on a cell face lands in the far cell.
        end = np.array([x, y]) + direction[hit] * (reach[hit] + 0.05 * self.resolution)[:, None]
        hit_r, hit_c = self._cells_where(end[:, 0], end[:, 1], np.ones(len(end), dtype=bool))
        if free_r.size + hit_r.size == 0:
            return
        # Mark the cells in a window around the scan (one update per cell; hit wins over free), then update.
        all_r, all_c = np.concatenate([free_r, hit_r]), np.concatenate([free_c, hit_c])
        r0, r1 = all_r.min(), all_r.max() + 1
        c0, c1 = all_c.min(), all_c.max() + 1
        mark = np.zeros((r1 - r0, c1 - c0), dtype=np.int8)
        mark[free_r - r0, free_c - c0] = 1
        mark[hit_r - r0, hit_c - c0] = 2
        window = self.log_odds[r0:r1, c0:c1]
        lo, hi = self.params.clamp
        free, occupied = mark == 1, mark == 2
        window[free] = np.maximum(window[free] + self.params.l_free, lo)
        window[occupied] = np.minimum(window[occupied] + self.params.l_occ, hi)
        self.version += 1

    def _cells_where(self, px: np.ndarray, py: np.ndarray, where: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(rows, cols) of the in-bounds cells holding the world points (px, py) (m) selected by ``where``.

        The same cells as :meth:`world_to_cell` gives, computed on the arrays as they are (no stacking).
        """
        x0, y0 = self.origin
        rows, cols = self.shape
        col = np.floor((px - x0) / self.resolution).astype(int)
        row_up = np.floor((py - y0) / self.resolution).astype(int)
        keep = where & (col >= 0) & (col < cols) & (row_up >= 0) & (row_up < rows)
        return rows - 1 - row_up[keep], col[keep]

    def occupied_mask(self) -> np.ndarray:
        """Bool (rows, cols): cells believed occupied."""
        return self.log_odds > self.params.occupied_threshold

    def occupied_cells(self, rc: np.ndarray) -> np.ndarray:
        """Bool (N,): whether each cell (row, col) of ``rc`` (N, 2) is believed occupied; cells off the grid are not
        (what :meth:`occupied_mask` says of a few cells, without working it out for the whole grid)."""
        rc = np.atleast_2d(np.asarray(rc))
        inside = self.in_bounds(rc)
        out = np.zeros(len(rc), dtype=bool)
        out[inside] = self.log_odds[rc[inside, 0], rc[inside, 1]] > self.params.occupied_threshold
        return out

    def free_mask(self) -> np.ndarray:
        """Bool (rows, cols): cells believed free."""
        return self.log_odds < self.params.free_threshold

    def unknown_mask(self) -> np.ndarray:
        """Bool (rows, cols): cells neither free nor occupied."""
        return ~(self.occupied_mask() | self.free_mask())

    def explored_centre(self) -> tuple[float, float] | None:
        """Centroid (x m, y m, world frame) of the known-free cells, or None if there are none."""
        rows, cols = np.nonzero(self.free_mask())
        if rows.size == 0:
            return None
        x, y = self.cell_to_world(np.array([[rows.mean(), cols.mean()]]))[0]
        return float(x), float(y)

    def to_image(self) -> np.ndarray:
        """uint8 (rows, cols) image, row 0 on top: free 254, occupied 0, unknown 205 (map_server greys)."""
        image = np.full(self.shape, UNKNOWN_GREY, dtype=np.uint8)
        image[self.free_mask()] = FREE_GREY
        image[self.occupied_mask()] = OCCUPIED_GREY
        return image

    def copy(self) -> OccupancyGrid:
        """An independent copy (same params, copied log-odds)."""
        other = OccupancyGrid.__new__(OccupancyGrid)
        other.params = self.params
        other.log_odds = self.log_odds.copy()
        other.version = self.version
        return other


def mapped_plan(plan: Floorplan, resolution_m: float = 0.1) -> OccupancyGrid:
    """A grid over ``plan``'s extent mapped as the plan has it: a cell holding any wall pixel occupied (a wall
    thinner than a cell is mapped, as a laser maps it), every other cell free, at log-odds 3 and -2. The robot's
    map had it seen the whole building, for measuring on true plans what the navigator reads off its own."""
    grid = OccupancyGrid(OccupancyParams(resolution_m=resolution_m, bounds=plan.extent))
    grid.log_odds[:] = -2.0
    cells = grid.world_to_cell(plan.pixel_to_world(np.argwhere(plan.occupied)))
    inside = grid.in_bounds(cells)
    grid.log_odds[cells[inside, 0], cells[inside, 1]] = 3.0
    return grid


def pool_cells(values: np.ndarray, factor: int, fill: float | bool, reduce: Callable[..., np.ndarray]) -> np.ndarray:
    """``values`` (rows, cols) in blocks of ``factor`` x ``factor`` cells, each block reduced to one cell by
    ``reduce`` (e.g. ``np.min``, ``np.any``, called with ``axis``); the edges are padded with ``fill``."""
    rows, cols = values.shape
    pr, pc = -(-rows // factor) * factor, -(-cols // factor) * factor
    padded = np.full((pr, pc), fill, dtype=values.dtype)
    padded[:rows, :cols] = values
    return reduce(padded.reshape(pr // factor, factor, pc // factor, factor), axis=(1, 3))


def unpool_cells(values: np.ndarray, factor: int, shape: tuple[int, int]) -> np.ndarray:
    """Each cell of pooled ``values`` repeated over its ``factor`` x ``factor`` block, cut to ``shape``."""
    return np.repeat(np.repeat(values, factor, axis=0), factor, axis=1)[:shape[0], :shape[1]]
